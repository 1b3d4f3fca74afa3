"""Reading a user's configuration: YAML files read safely, a camera's credentials file, and a validation
error told in one line naming the file, the field and the value (:class:`ScenarioError`)."""

from collections.abc import Hashable
from pathlib import Path

import pydantic
import yaml

from ptztrack.files import SHOWN_CHARACTERS, InputError, read_text, shown

SCENARIO_MAX_BYTES = 1_000_000
YAML_MAX_VALUES = 100_000
"""How many values a scenario may hold once YAML's aliases are expanded (a 'billion laughs' holds 10^9)."""


class ScenarioError(InputError):
    """A scenario that cannot be run; the message is one line naming the field and value."""


FILE_KINDS: dict[str, type[pydantic.BaseModel]] = {}
"""The kinds of configuration file by name ('scenario', 'dataset', 'camera calibration'), each added by the
module of its model, so that a file of one kind given as another is told as that mix-up."""


def refuse_another_kind(path: str | Path, data: dict, kind: str) -> None:
    """Refuse, naming the mix-up, a file of another kind of :data:`FILE_KINDS` given as a ``kind`` file: every
    key that ``kind``'s model lacks is a field of the other's, and the file has each field that the other
    requires and ``kind``'s lacks."""
    own = set(FILE_KINDS[kind].model_fields)
    strange = set(data) - own
    for other_kind, other in FILE_KINDS.items():
        required = {name for name, field in other.model_fields.items() if field.is_required()} - own
        if other_kind != kind and strange and strange <= set(other.model_fields) and required <= set(data):
            keys = ", ".join(sorted(strange))
            raise ScenarioError(f"{path}: a {other_kind} file (it has {keys}), not a {kind} file")


def _first_error_line(error: pydantic.ValidationError, source: str) -> str:
    first = error.errors()[0]
    field = ".".join(str(part) for part in first["loc"])[:SHOWN_CHARACTERS] or "(top level)"
    message = first["msg"]
    if first["type"] == "extra_forbidden":
        message = "unknown key"
    elif first["type"] == "value_error":
        message = str(first["ctx"]["error"])
    if isinstance(first["input"], dict):  # a section's own check, whose message names its fields
        return f"{source}: {field}: {message}"
    return f"{source}: {field}: {message} (got {shown(first['input'])})"


class _LimitedLoader(yaml.SafeLoader):
    """YAML's safe loader, refusing duplicate keys (YAML forbids them; PyYAML keeps the last) and keys that
    are lists or mappings (which name no field)."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if not isinstance(key, Hashable):  # a list or a mapping as a key: no name for a field
                raise yaml.constructor.ConstructorError(
                    "while reading a mapping", node.start_mark, "a key that is a list or a mapping", key_node.start_mark
                )
            if key in seen:
                raise _DuplicateKey(key, key_node.start_mark.line + 1)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


class _DuplicateKey(Exception):
    def __init__(self, key, line: int):
        super().__init__(key, line)
        self.key, self.line = key, line


def _expanded_values(node: yaml.Node, limit: int) -> int:
    """How many values ``node`` holds with every alias expanded, counting no further than past ``limit``.

    An alias is the node it names, so a shared node is counted once per reference; the sizes are
    memoised per node, which takes time linear in the document even when the expansion is exponential.
    """
    sizes: dict[int, int] = {}

    def size(current: yaml.Node) -> int:
        if id(current) in sizes:
            return sizes[id(current)]
        sizes[id(current)] = limit + 1  # a node reached again while being sized is a cycle
        if isinstance(current, yaml.SequenceNode):
            total = 1 + sum(size(child) for child in current.value)
        elif isinstance(current, yaml.MappingNode):
            total = 1 + sum(size(key) + size(value) for key, value in current.value)
        else:
            total = 1
        sizes[id(current)] = min(total, limit + 1)
        return sizes[id(current)]

    return size(node)


def read_yaml(path: str | Path, what: str, error_type: type[InputError]) -> object:
    """A user's YAML file, read safely: at most 1 MB of UTF-8 and 100 000 values once aliases are
    expanded, no duplicate keys; any problem is ``error_type`` naming the file and the line."""
    path = Path(path)
    text = read_text(path, what, SCENARIO_MAX_BYTES, error_type)
    try:
        loader = _LimitedLoader(text)
    except yaml.YAMLError as error:  # characters YAML does not allow, found as the reader starts
        raise error_type(f"{path}: not valid YAML ({shown(str(error).splitlines()[0])})") from None
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        if _expanded_values(node, YAML_MAX_VALUES) > YAML_MAX_VALUES:
            raise error_type(
                f"{path}: more than {YAML_MAX_VALUES} values once its aliases are expanded; expected a {what} file"
            )
        return loader.construct_document(node)
    except _DuplicateKey as duplicate:
        raise error_type(f"{path}: line {duplicate.line}: key {shown(duplicate.key)} appears twice") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise error_type(f"{path}: not valid YAML{where}") from None
    except RecursionError:
        raise error_type(f"{path}: YAML nested too deeply for a {what} file") from None
    finally:
        loader.dispose()


def load_credentials(path: str | Path, username_elsewhere: bool = False) -> dict[str, str]:
    """A camera's credentials file: a YAML (or JSON) mapping of a non-empty ``username`` and ``password``;
    with ``username_elsewhere`` (the user given in the camera's URL, or by ``--user``) the username may be
    left out. Any problem is a :class:`ScenarioError` naming the file and the field, never the password."""
    data = read_yaml(path, "credentials", ScenarioError)
    expected = "expected a mapping with username and password"
    if not isinstance(data, dict) or not set(data) <= {"username", "password"}:
        raise ScenarioError(f"{path}: {expected}")
    for field in ("password",) if username_elsewhere else ("username", "password"):
        if data.get(field) in (None, ""):
            raise ScenarioError(f"{path}: {field}: missing or empty; {expected}")
    return {key: str(value) for key, value in data.items()}
