"""The layers a drawing can show, and what each one needs computed.

Owns the rule *a scene computes only what it shows*: every layer states the
derivative order of the position functions it needs (0 positions, 1 velocity
analogs, 2 acceleration analogs) and whether it needs the dynamics plug-in; a scene
asks the kinematics for the largest order among its layers and nothing more (the
reactions layer asks the dynamics plug-in, which solves its own motion).

Examples
--------
>>> layers = parse_layers("assur,velocity")
>>> layers
('assur', 'velocity')
>>> kinematic_order(layers), kinematic_order(()), kinematic_order(("acceleration",))
(1, 0, 2)
>>> parse_layers("speed")
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: show: unknown layer 'speed' (known: acceleration, assur, \
inertia, loads, paths, reactions, targets, velocity)
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterable
from dataclasses import dataclass

from mjstruct.errors import MechanismError


@dataclass(frozen=True)
class Layer:
    """One optional layer of a drawing.

    Attributes
    ----------
    name : what ``--show`` calls it.
    order : derivative order of the position functions it needs.
    dynamics : whether it needs the dynamics plug-in (``mjstruct.dynamics``).
    help : one line for ``--help`` and the docs.
    """

    name: str
    order: int
    dynamics: bool
    help: str


LAYERS: dict[str, Layer] = {
    layer.name: layer
    for layer in (
        Layer("assur", 0, False, "links coloured by the Assur group that places them"),
        Layer("velocity", 1, False, "velocity vectors at moving joints and points"),
        Layer("acceleration", 2, False, "acceleration vectors at moving joints and points"),
        Layer("paths", 0, False, "trajectories of chosen points over the cycle"),
        Layer("loads", 0, True, "applied forces and moments (dynamics plug-in)"),
        Layer("inertia", 2, True, "inertia forces and moments (dynamics plug-in)"),
        Layer("reactions", 0, True, "joint reactions (dynamics plug-in)"),
        Layer("targets", 0, False, "a synthesised mechanism's targets (shown with paths)"),
    )
}


def dynamics_available() -> bool:
    """Whether the dynamics plug-in is installed."""
    return importlib.util.find_spec("mjstruct.dynamics") is not None


def parse_layers(text: str | Iterable[str] | None, name: str = "show") -> tuple[str, ...]:
    """Layer names from ``"a,b"`` (or an iterable), checked; ``name`` is used in errors.

    Raises
    ------
    MechanismError
        an unknown layer, or a dynamics layer without the dynamics plug-in.
    """
    if text is None:
        return ()
    items = text.split(",") if isinstance(text, str) else list(text)
    out: list[str] = []
    for raw in items:
        layer = raw.strip().lower()
        if not layer:
            continue
        if layer not in LAYERS:
            known = ", ".join(sorted(LAYERS))
            raise MechanismError(f"{name}: unknown layer {layer!r} (known: {known})")
        if LAYERS[layer].dynamics and not dynamics_available():
            raise MechanismError(
                f"{name}: layer {layer!r} needs the dynamics plug-in (mjstruct.dynamics), "
                "which is not installed"
            )
        if layer not in out:
            out.append(layer)
    return tuple(out)


def kinematic_order(layers: Iterable[str]) -> int:
    """The derivative order a scene with ``layers`` must ask for."""
    return max((LAYERS[x].order for x in layers), default=0)
