"""The notebook-picture seam: the model's ``_repr_svg_`` asks :mod:`mjstruct.display`,
and the renderer the package installs (the drawings) answers."""

from __future__ import annotations

from mjstruct import display
from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism


def test_model_shows_no_picture_without_a_renderer():
    m = read_mechanism(example_path("four-bar"))
    previous = display.set_svg_renderer(None)
    try:
        assert m._repr_svg_() is None
    finally:
        display.set_svg_renderer(previous)


def test_installed_renderer_draws_the_mechanism():
    m = read_mechanism(example_path("four-bar"))
    svg = m._repr_svg_()
    assert svg is not None and svg.lstrip().startswith("<?xml") and "<svg" in svg


def test_renderer_sees_the_object_asked_about():
    seen: list[object] = []
    m = read_mechanism(example_path("four-bar"))
    previous = display.set_svg_renderer(lambda obj: seen.append(obj) or "<svg/>")
    try:
        assert m._repr_svg_() == "<svg/>"
    finally:
        display.set_svg_renderer(previous)
    assert seen == [m]
