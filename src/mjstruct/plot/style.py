"""How a drawing looks: sizes as fractions of the mechanism's size, and colours.

Owns the constants every artist of a scheme reads, so that a pin, a bar, a vector's
colour or the Assur groups' palette is defined once.
"""

from __future__ import annotations

#: pin radius as a fraction of the mechanism's size
PIN = 0.018
#: the longest velocity / acceleration arrow as a fraction of the mechanism's size
ARROW = 0.28

LINK_COLOUR = "#34495e"
FRAME_COLOUR = "0.35"
DRIVER_COLOUR = "crimson"
#: Assur groups: tab10 without its pink and grey (kept apart from the vectors, the frame)
GROUP_COLOURS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#bcbd22",
    "#17becf",
)
#: vectors in colours outside the group palette, with a white halo, so that an arrow
#: stays visible on a link of any colour
VELOCITY_COLOUR = "black"
ACCELERATION_COLOUR = "#e6008a"
FORCE_COLOURS = {"loads": "#0a3dff", "inertia": "indigo", "reactions": "darkred"}
HALO = "white"
