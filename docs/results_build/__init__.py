"""The results pages' fields, a module per page, for docs/build_results.py.

Each page module has ``fields(load)``, the page's ``{{ name }}`` values, and (but the speed page)
``headline(load)``, the page's row of the index's table; ``load(name)`` is the JSON file
``data/<name>.json``, passed by the builder so that every path is read through its one ``load``.
"""

from collections.abc import Callable
from typing import Any

Load = Callable[[str], Any]
