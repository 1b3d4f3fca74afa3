"""Names for implementations of the roles, so that scenario files and the command line can use them.

Four kinds: ``policies``, ``detectors``, ``cameras`` (camera backends) and
``trackers``. A name maps to a *factory*, called by the builders
(:mod:`ptztrack.builders`) with the validated scenario and what is built so far:

* ``policies`` and ``trackers``: ``factory(scenario, world) -> Policy | Tracker``,
  ``world`` a :class:`ptztrack.loop.steps.World`;
* ``detectors`` and ``cameras``: ``factory(scenario, scene) -> Detector | CameraBackend``,
  ``scene`` a :class:`ptztrack.builders.world.BuiltScene`.

Names come from three places, in this order of precedence: ptztrack's own
(imported only when used), the entry points of installed packages in the
groups ``ptztrack.policies``, ``ptztrack.detectors``, ``ptztrack.cameras``
and ``ptztrack.trackers``, and :func:`register` at run time (in that process only: the ``ptztrack``
command finds another package's names through its entry points)::

    # pyproject.toml of another package
    [project.entry-points."ptztrack.policies"]
    greedy = "my_package.policies:make_greedy"

A name that ptztrack has replaced (:data:`RENAMED`) is still taken wherever a
name is, with one warning line naming the current one (:func:`current_name`).

This module imports nothing else of ptztrack: the built-in factories are
named by their import paths.
"""

import functools
import importlib
import logging
from collections.abc import Callable
from importlib.metadata import entry_points
from typing import Any

KINDS = ("policies", "detectors", "cameras", "trackers")
ENTRY_POINT_GROUPS = {kind: f"ptztrack.{kind}" for kind in KINDS}
_SINGULAR = {"policies": "policy", "detectors": "detector", "cameras": "camera backend", "trackers": "tracker"}

_FACTORIES = "ptztrack.builders.factories"
_FOLLOW = "ptztrack.builders.follow"
_BUILT_IN: dict[str, dict[str, str]] = {
    "policies": {
        **{name: f"{_FACTORIES}:{name}_policy" for name in ("fix", "patrol")},
        "rnd": f"{_FACTORIES}:random_policy",
        **{name: f"{_FACTORIES}:{name}_policy" for name in ("intg", "smpl")},
        "follow": f"{_FOLLOW}:follow_policy",
    },
    "detectors": {name: f"{_FACTORIES}:{name}_detector" for name in ("ideal", "realistic", "hog", "detections")},
    "cameras": {"simulated": f"{_FACTORIES}:simulated_camera", "virtual": f"{_FACTORIES}:virtual_camera"},
    "trackers": {
        "ekf": f"{_FACTORIES}:ekf_tracker",
        **{name: f"{_FOLLOW}:{name}_tracker" for name in ("particle", "csrt", "mil")},
    },
}
_registered: dict[str, dict[str, Callable[..., Any]]] = {kind: {} for kind in KINDS}
RENAMED: dict[str, dict[str, str]] = {"policies": {"random": "rnd"}, "detectors": {}, "cameras": {}, "trackers": {}}
"""Former names of built-in implementations, by kind: {former: current}. One spelling per policy, the one
the PTZ paper's tables print and ``experiment`` took ('rnd'), for every command and file."""
_warned: set[tuple[str, str]] = set()
log = logging.getLogger(__name__)


class UnknownName(ValueError):
    """A name that no implementation of the kind has; the message lists the names there are."""


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}; expected one of {', '.join(KINDS)}")


@functools.cache
def _entry_points(kind: str) -> dict:
    return {point.name: point for point in entry_points(group=ENTRY_POINT_GROUPS[kind])}


def names(kind: str) -> list[str]:
    """Every name of the kind: the built-in ones first, then installed, then registered at run time."""
    _check_kind(kind)
    return list(dict.fromkeys([*_BUILT_IN[kind], *_entry_points(kind), *_registered[kind]]))


def current_name(kind: str, name: str) -> str:
    """``name``, or the current name of a former one (:data:`RENAMED`), said once per process in a warning
    line."""
    _check_kind(kind)
    current = RENAMED[kind].get(name)
    if current is None:
        return name
    if (kind, name) not in _warned:
        _warned.add((kind, name))
        log.warning(
            f"the {_SINGULAR[kind]} {name!r} is now called {current!r} (the old name will go in a later release)"
        )
    return current


def factory(kind: str, name: str) -> Callable[..., Any]:
    """The factory registered for ``name`` (or for the current name of a former one); raises
    :class:`UnknownName` naming the choices."""
    name = current_name(kind, name)
    if name in _BUILT_IN[kind]:
        module, _, attribute = _BUILT_IN[kind][name].partition(":")
        return getattr(importlib.import_module(module), attribute)
    if name in _entry_points(kind):
        return _entry_points(kind)[name].load()
    if name in _registered[kind]:
        return _registered[kind][name]
    raise UnknownName(f"unknown {_SINGULAR[kind]} {name!r}; expected one of {', '.join(names(kind))}")


def register(kind: str, name: str, make: Callable[..., Any] | None = None):
    """Register ``make`` as the factory of ``name`` in this process (the ``ptztrack`` command, a process of its
    own, finds another package's names through its entry points); without ``make``, a decorator that does so.

    A name that is taken (built in, a former built-in name, installed, or registered before) is refused.
    """
    _check_kind(kind)

    def add(make: Callable[..., Any]) -> Callable[..., Any]:
        if name in names(kind) or name in RENAMED[kind]:
            raise ValueError(f"{kind}: the name {name!r} is taken")
        _registered[kind][name] = make
        return make

    return add if make is None else add(make)


def unregister(kind: str, name: str) -> None:
    """Forget a name registered at run time (built-in and installed names stay)."""
    _check_kind(kind)
    _registered[kind].pop(name, None)
