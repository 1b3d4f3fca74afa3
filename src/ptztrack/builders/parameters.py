"""From a validated configuration section to the maths' parameter dataclass it maps onto."""

from dataclasses import fields
from typing import TYPE_CHECKING, TypeVar

from pydantic import BaseModel

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

P = TypeVar("P", bound="DataclassInstance")


def parameters_from(section: BaseModel, parameters_type: type[P], **overrides) -> P:
    """``parameters_type`` (a dataclass of the maths) with the values of the fields that the configuration
    ``section`` shares with it, then ``overrides``: the section's defaults are the dataclass's own."""
    shared = {field.name for field in fields(parameters_type)} & set(type(section).model_fields)
    return parameters_type(**{name: getattr(section, name) for name in shared} | overrides)
