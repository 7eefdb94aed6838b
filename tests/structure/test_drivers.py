"""One driver check for every command: ids, repetitions, count and independence."""

from __future__ import annotations

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import assur_groups
from mjstruct.structure.drivers import driver_balance, validate_drivers


def example(name: str) -> Mechanism:
    return read_mechanism(example_path(name))


def test_the_files_drivers_are_returned_as_a_tuple():
    assert validate_drivers(example("five-bar")) == ("O1", "O2")
    assert validate_drivers(example("four-bar"), ["O2"]) == ("O2",)


def test_unknown_and_repeated_joints_name_the_parameter():
    four = example("four-bar")
    with pytest.raises(MechanismError, match=r"^drivers: 'X' is not a joint id$"):
        validate_drivers(four, ["O1", "X"])
    with pytest.raises(MechanismError, match=r"^drivers: joint 'O1' is listed twice$"):
        validate_drivers(four, ["O1", "O1"])
    with pytest.raises(MechanismError, match=r"^drivers: 3 is not a joint id$"):
        validate_drivers(four, [3])  # type: ignore[list-item]


def test_no_driver_on_a_mobile_chain_is_refused():
    with pytest.raises(MechanismError, match=r"^drivers: none given.*under-driven \(F = 1"):
        validate_drivers(example("four-bar"), [])
    # a structure (F = 0) needs none
    triangle = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0])], frame=0)
    assert validate_drivers(triangle) == ()


@pytest.mark.parametrize(
    ("name", "drivers", "redundant"),
    [
        ("four-bar", ["O1", "O2"], ("O2",)),
        ("four-bar", ["O1", "B"], ("B",)),
        ("four-bar", ["O1", "A", "B"], ("A", "B")),
        ("slider-crank", ["O1", "A"], ("A",)),
        ("slider-crank", ["O1", "B"], ("B",)),
        ("scotch-yoke", ["O", "J"], ("J",)),
    ],
)
def test_redundant_drivers_are_over_constrained_and_named(name, drivers, redundant):
    m = example(name)
    b = driver_balance(m, drivers)
    assert (b.redundant_drivers, b.dof_left) == (redundant, 0)
    with pytest.raises(MechanismError) as info:
        validate_drivers(m, drivers)
    text = str(info.value)
    assert text.startswith("drivers: ") and "over-constrained" in text
    assert "under" not in text and f"({', '.join(redundant)} already fixed" in text


def test_too_few_drivers_are_under_driven():
    b = driver_balance(example("five-bar"), ["O1"])
    assert (b.redundant_drivers, b.dof_left, b.F_generic) == ((), 1, 2)
    with pytest.raises(MechanismError, match=r"under-driven \(1 DOF left.*generic F = 2"):
        validate_drivers(example("five-bar"), ["O1"])


def test_enough_drivers_one_redundant_one_missing():
    # five-bar (F = 2) carrying a rigid double four-bar on link 4: D sits inside it
    m = Mechanism.build(
        [("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("C", [3, 4]), ("O2", [4, 0]),
         ("D", [4, 5]), ("E", [5, 6]), ("G", [6, 7]), ("H", [7, 4]), ("I", [5, 7])],
        frame=0,
    )  # fmt: skip
    b = driver_balance(m, ["O1", "D"])
    assert (b.F_generic, b.redundant_drivers, b.dof_left) == (2, ("D",), 1)
    assert b.structural_redundant == 1 and not b.balanced
    with pytest.raises(MechanismError, match=r"over-constrained .* and under-driven"):
        validate_drivers(m, ["O1", "D"])


def _double_parallelogram() -> Mechanism:
    joints = [{"id": f"O{k}", "links": ["0", str(k)], "at": [k - 1.0, 0.0]} for k in (1, 2, 3)]
    joints += [{"id": f"A{k}", "links": [str(k), "4"], "at": [k - 0.5, 1.0]} for k in (1, 2, 3)]
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def test_a_known_mobility_overrides_the_generic_one():
    m = _double_parallelogram()  # generically a structure, mobile at this geometry
    with pytest.raises(MechanismError, match="over-constrained"):
        validate_drivers(m)
    assert validate_drivers(m, mobility=1) == ("O1",)
    with pytest.raises(MechanismError, match=r"over-constrained \(mobility F = 1, 2 drivers"):
        validate_drivers(m, ["O1", "O2"], mobility=1)
    with pytest.raises(MechanismError, match=r"under-driven \(mobility F = 2, 1 driver"):
        validate_drivers(m, ["O1"], mobility=2)
    # equal to the generic DOF: independence is checked as well
    with pytest.raises(MechanismError, match=r"\(B already fixed"):
        validate_drivers(example("four-bar"), ["O1", "B"], mobility=1)


def test_balance_false_checks_ids_only():
    four = example("four-bar")
    assert validate_drivers(four, ["O1", "O2"], balance=False) == ("O1", "O2")
    with pytest.raises(MechanismError, match="listed twice"):
        Mechanism.build([("O1", [0, 1]), ("A", [1, 0])], frame=0, drivers=["O1", "O1"])


def test_assur_refuses_redundant_drivers():
    with pytest.raises(MechanismError, match="over-constrained"):
        assur_groups(example("four-bar"), ["O1", "A", "B"])


@pytest.mark.parametrize(
    ("drivers", "words"),
    [
        ("O1,A,B", "over-constrained (A, B already fixed"),
        ("O1,O1", "joint 'O1' is listed twice"),
        ("O1,X", "'X' is not a joint id"),
        ("", "none given"),
    ],
)
def test_cli_assur_driver_errors_exit_2_naming_the_flag(capsys, drivers, words):
    path = str(example_path("four-bar"))
    assert main(["assur", path, "--drivers", drivers]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("mjstruct assur: --drivers: ") and captured.err.count("\n") == 1
    assert words in captured.err


def test_cli_slider_crank_o1_a_is_over_constrained_not_under(capsys):
    assert main(["assur", str(example_path("slider-crank")), "--drivers", "O1,A"]) == 2
    err = capsys.readouterr().err
    assert "over-constrained" in err and "under" not in err


@pytest.mark.parametrize("mobility", [None, 0, 1, 2])
@pytest.mark.parametrize("name", ["four-bar", "five-bar", "slider-crank", "watt"])
def test_one_game_judged_as_validate_drivers_judges(name, mobility):
    """check_balance on a played game refuses and accepts what validate_drivers does
    (the planner plays the game once for its check and for the decomposition)."""
    import itertools

    from mjstruct.structure.drivers import check_balance

    m = example(name)
    ids = [j.id for j in m.joints]
    for k in range(3):
        for drivers in itertools.combinations(ids, k):
            try:
                expected: object = validate_drivers(m, drivers, mobility=mobility)
            except MechanismError as e:
                expected = str(e)
            try:
                got: object = check_balance(driver_balance(m, drivers), mobility=mobility).drivers
            except MechanismError as e:
                got = str(e)
            assert got == expected
