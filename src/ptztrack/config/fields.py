"""The pieces the configuration models are built from: the strict base model, bounded field types
(each bound with its reason) and fields that name a registered implementation."""

from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from ptztrack import registry
from ptztrack.names import MAX_FRAMES

PositiveFloat = Annotated[float, Field(gt=0)]
NonNegativeFloat = Annotated[float, Field(ge=0)]


def at_most(limit: float, why: str):
    """A bound on a size, count or rate, with the reason for it (memory, time, physics) in the message."""

    def check(value):
        if value > limit:
            raise ValueError(f"must be at most {limit:g} ({why})")
        return value

    return AfterValidator(check)


def at_most_items(limit: int, why: str):
    """A bound on the length of a list, with the reason for it."""

    def check(values):
        if len(values) > limit:
            raise ValueError(f"must have at most {limit} items ({why})")
        return values

    return AfterValidator(check)


_MAX_FRAMES = MAX_FRAMES
Pixels = Annotated[int, Field(gt=0), at_most(8192, "memory: an 8192 x 8192 colour image is 200 MB")]
Degrees = Annotated[float, Field(ge=-360), at_most(360, "an angle in degrees")]


def _registered(kind: str):
    """A field that names an implementation registered under ``kind`` (:mod:`ptztrack.registry`); a former
    name becomes the current one."""

    def check(name: str | None) -> str | None:
        if name is None:
            return None
        name = registry.current_name(kind, name)
        if name not in registry.names(kind):
            raise ValueError(f"expected one of {', '.join(registry.names(kind))}")
        return name

    return AfterValidator(check)


Options = dict[str, Any]
"""Parameters of an implementation registered by another package, passed to its factory unread."""


class _Strict(BaseModel):
    # Every float is finite: no field gives infinity a meaning.
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


_Coordinate = Annotated[float, Field(ge=-10_000), at_most(10_000, "metres: the ground a camera can see")]


_Zoom = Annotated[float, Field(ge=1), at_most(100, "a PTZ camera's optical zoom")]
