"""MkDocs hook: the reference pages' lists generated from the code at build time, so no page holds a
hand-written copy of an option or a field.

A line ``<!-- generated: NAME -->`` of a page is replaced by:

- ``command-line``: every ``ptztrack`` command from the argparse parser (:func:`ptztrack.cli.parser`): its
  help, its usage, and each argument with what it takes and its help as ``--help`` prints it (defaults
  included);
- ``scenario``: every field of a scenario file from its pydantic model (:class:`ptztrack.config.Scenario`),
  section by section: type, default, bounds and the field's description from its model's docstring;
- ``dataset``: the same for a dataset file (:class:`ptztrack.config.MultiViewDataset`);
- ``calibration``: the same for a real camera's calibration file
  (:class:`ptztrack.config.CameraCalibrationFile`);
- ``service``: the same for ``ptztrack serve``'s configuration file
  (:class:`ptztrack.service.config.ServiceConfig`);
- ``service-example``: ``examples/serve.yaml`` as it is, in a ``yaml`` fence.
"""

import argparse
import inspect
import re
import sys
import types
import typing
from collections.abc import Callable, Iterator
from pathlib import Path

import pydantic
from pydantic.fields import FieldInfo

# The reference describes the code beside these pages, whichever ptztrack is installed.
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "src"))

MARKER = re.compile(r"^<!-- generated: ([a-z-]+) -->$", re.MULTILINE)


def on_page_markdown(markdown: str, **_) -> str:
    """MkDocs' hook: each marker line replaced by its generated Markdown."""
    return MARKER.sub(lambda found: GENERATORS[found.group(1)](), markdown)


# ---- the command line


def command_line() -> str:
    """Every command of ``ptztrack``, one section each, in the parser's order."""
    from ptztrack.cli.arguments import parser

    return "\n".join(_command_sections(parser(), ["ptztrack"], None))


def _subcommands(command: argparse.ArgumentParser) -> argparse._SubParsersAction | None:
    return next((each for each in command._actions if isinstance(each, argparse._SubParsersAction)), None)


def _command_sections(command: argparse.ArgumentParser, words: list[str], summary: str | None) -> Iterator[str]:
    choose = _subcommands(command)
    arguments = [each for each in command._actions if not isinstance(each, argparse._SubParsersAction)]
    if len(words) > 1:
        level = "#" * min(len(words), 4)
        yield f"{level} `{' '.join(words)}`\n"
    if summary:
        yield summary[0].upper() + summary[1:] + ".\n"
    usage = command.format_usage().removeprefix("usage: ").strip()
    yield f"```text\n{usage}\n```\n"
    if arguments:
        yield from _argument_table(command, arguments)
    if choose is not None:
        helps = {each.dest: each.help for each in choose._choices_actions}
        for name, sub in choose.choices.items():
            yield from _command_sections(sub, [*words, name], helps.get(name))


def _argument_table(command: argparse.ArgumentParser, arguments: list[argparse.Action]) -> Iterator[str]:
    formatter = command._get_formatter()
    yield "| argument | what it does |\n|---|---|"
    for action in arguments:
        invocation = formatter._format_action_invocation(action)
        text = formatter._expand_help(action) if action.help else ""
        yield f"| `{_cell(invocation)}` | {_cell(text)} |"
    yield ""


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


# ---- the configuration files


def scenario() -> str:
    from ptztrack.config import Scenario

    return _model_sections(Scenario, "top level")


def dataset() -> str:
    from ptztrack.config import MultiViewDataset

    return _model_sections(MultiViewDataset, "top level")


def calibration() -> str:
    from ptztrack.config import CameraCalibrationFile

    return _model_sections(CameraCalibrationFile, "top level")


def service() -> str:
    from ptztrack.service.config import ServiceConfig

    return _model_sections(ServiceConfig, "top level")


def service_example() -> str:
    return "```yaml\n" + (ROOT / "examples" / "serve.yaml").read_text(encoding="utf-8").rstrip("\n") + "\n```"


def _model_sections(model: type[pydantic.BaseModel], title: str) -> str:
    """One table per model, the top one first, then each section's model where it first appears."""
    sections: list[str] = []
    seen: set[type] = set()
    queue: list[tuple[str, type[pydantic.BaseModel]]] = [(title, model)]
    while queue:
        path, current = queue.pop(0)
        if current in seen:
            continue
        seen.add(current)
        heading = f"### {path}" if path == title else f"### `{path}`"
        header = ["| field | type | default | bounds | meaning |", "|---|---|---|---|---|"]
        lines = [heading, "", _first_paragraph(current), "", *header]
        descriptions = _field_descriptions(current)
        for name, info in current.model_fields.items():
            lines.append(
                f"| `{name}` | {_cell(_type_name(info.annotation))} | {_cell(_default(info))} | "
                f"{_cell(_bounds(info))} | {_cell(descriptions.get(name, ''))} |"
            )
            for nested in _nested_models(info.annotation):
                queue.append((name if path == title else f"{path}.{name}", nested))
        sections.append("\n".join(lines) + "\n")
    return "\n".join(sections)


def _own_doc(model: type) -> str:
    """The class's own docstring (not one inherited from pydantic's base model), in Markdown."""
    doc = inspect.cleandoc(vars(model).get("__doc__") or "")
    doc = re.sub(r":[a-z]+:`~?([^`]*?)`", lambda found: f"`{found.group(1).rsplit('.', 1)[-1]}`", doc)
    return doc.replace("``", "`")


_NAMES = r"[a-z_][a-z0-9_]*(?:, [a-z_][a-z0-9_]*)*"
_DESCRIBED = re.compile(rf"(?:^|(?<=; )|(?<=\. )|(?<=\n)|(?<=, and ))({_NAMES}) : ")


def _first_paragraph(model: type) -> str:
    """The model's summary: its docstring's first paragraph, up to the first field it describes."""
    first = " ".join(_own_doc(model).split("\n\n")[0].split())
    found = _DESCRIBED.search(first)
    return first[: found.start()].strip() if found else first


def _field_descriptions(model: type[pydantic.BaseModel]) -> dict[str, str]:
    """What a field means, from the ``name : text`` entries of the model's docstring, of the models it
    inherits from and of the docstrings of the parameter classes its defaults come from (``a, b : text``
    describes both); a field named with a parameter class's prefix takes that class's entry
    (``hog_upsample``, HogParameters's ``upsample``)."""
    found: dict[str, str] = {}
    for each in _docstring_sources(model):
        parameters = not issubclass(each, pydantic.BaseModel)
        prefix = each.__name__.removesuffix("Parameters").lower() + "_" if parameters else ""
        for name, meaning in _entries(each).items():
            for field in (name, prefix + name):
                if field in model.model_fields:
                    found.setdefault(field, meaning)
    return found


def _entries(documented: type) -> dict[str, str]:
    """The ``name : text`` entries of a class's docstring."""
    entries: dict[str, str] = {}
    for paragraph in _own_doc(documented).split("\n\n"):
        text = " ".join(paragraph.split())
        found = list(_DESCRIBED.finditer(text))
        for index, entry in enumerate(found):
            end = found[index + 1].start() if index + 1 < len(found) else len(text)
            meaning = text[entry.end() : end].strip().removesuffix(";").removesuffix(", and").strip()
            for name in entry.group(1).split(", "):
                entries.setdefault(name, meaning)
    return entries


def _docstring_sources(model: type[pydantic.BaseModel]) -> list[type]:
    """The model itself first, then the models of :mod:`ptztrack` it inherits from, nearest first, then the
    parameter dataclasses of :mod:`ptztrack` their modules import."""
    # A subclass (the dataset's OccupancyTracker, of the scenario's Tracker) keeps its base's meanings,
    # which its base's docstring and the parameter classes of its base's module give.
    models = [each for each in model.__mro__ if _is_ptztrack_model(each)]
    others = [
        value
        for module in dict.fromkeys(inspect.getmodule(each) for each in models)
        for name, value in vars(module).items()
        if inspect.isclass(value) and name.endswith("Parameters") and value.__module__.startswith("ptztrack")
    ]
    return [*models, *dict.fromkeys(others)]


def _is_ptztrack_model(value: type) -> bool:
    return issubclass(value, pydantic.BaseModel) and value.__module__.startswith("ptztrack")


def _nested_models(annotation: object) -> Iterator[type[pydantic.BaseModel]]:
    if inspect.isclass(annotation) and issubclass(annotation, pydantic.BaseModel):
        yield annotation
        return
    for argument in typing.get_args(annotation):
        yield from _nested_models(argument)


def _type_name(annotation: object) -> str:
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _type_name(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_type_name(each) for each in typing.get_args(annotation))
    if origin is typing.Literal:
        return " or ".join(repr(each) for each in typing.get_args(annotation))
    if origin in (tuple, list, dict):
        inner = [_type_name(each) for each in typing.get_args(annotation) if each is not Ellipsis]
        if origin is tuple and ... not in typing.get_args(annotation):
            return "[" + ", ".join(inner) + "]"
        if origin is dict:
            return "mapping"
        return f"list of {inner[0]}" if inner else "list"
    if annotation is type(None):
        return "null"
    if inspect.isclass(annotation) and issubclass(annotation, pydantic.BaseModel):
        return f"section `{annotation.__name__}`"
    return getattr(annotation, "__name__", str(annotation))


def _default(info: FieldInfo) -> str:
    if info.is_required():
        return "required"
    value = info.get_default(call_default_factory=True)
    if isinstance(value, pydantic.BaseModel):
        return "its section's defaults"
    if value is None:
        return "null"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, tuple):
        value = list(value)
    return f"`{value}`" if value != {} else "`{}`"


def _bounds(info: FieldInfo) -> str:
    """The bounds of a field's value: pydantic's and those of ``at_most``, whatever their nesting."""
    found: list[str] = []
    for each in _constraints(info.annotation, list(info.metadata)):
        for attribute, sign in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(each, attribute, None)
            if value is not None:
                found.append(f"{sign} {value:g}" if isinstance(value, float) else f"{sign} {value}")
        limit = _at_most_limit(each)
        if limit is not None:
            found.append(f"<= {limit}")
    return ", ".join(dict.fromkeys(found))


def _constraints(annotation: object, metadata: list[object]) -> Iterator[object]:
    yield from metadata
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        _, *extra = typing.get_args(annotation)
        yield from _constraints(typing.get_args(annotation)[0], extra)
    elif origin in (typing.Union, types.UnionType):
        for each in typing.get_args(annotation):
            yield from _constraints(each, [])


def _at_most_limit(constraint: object) -> str | None:
    """The limit of a validator made by :func:`ptztrack.config.fields.at_most`, read from its closure."""
    function = getattr(constraint, "func", None)
    if not isinstance(constraint, pydantic.AfterValidator) or function is None or function.__closure__ is None:
        return None
    cells = dict(zip(function.__code__.co_freevars, (cell.cell_contents for cell in function.__closure__), strict=True))
    limit = cells.get("limit")
    if isinstance(limit, int | float) and function.__qualname__.startswith("at_most."):
        return f"{limit:g}"
    return None


GENERATORS: dict[str, Callable[[], str]] = {
    "command-line": command_line,
    "scenario": scenario,
    "dataset": dataset,
    "calibration": calibration,
    "service": service,
    "service-example": service_example,
}
