"""The SANDA2V deck as design parameters, and each of its consistency rules (Lowen & Tepper
1982, ARLCD-TR-82013: Input Data pp. 7-11, App. B, C, E, F)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from components.design_rules import DesignError
from components.gear_train import GearTrain
from components.m739_data import M739
from components.sanda2v_deck import (
    BOTH,
    BY_NAME,
    DECK,
    SHARED,
    TRAIN,
    VERGE,
    data_from,
    deck_variables,
    violations,
)
from components.units import DEG, INCH
from components.verge_escapement import VergeEscapement
from orchestrator.scenes.m739.monolithic import run_m739
from orchestrator.units import to_si

DESIGN_FILE = Path(__file__).resolve().parents[2] / "scenarios" / "designs" / "m739.toml"


def test_the_deck_is_fifteen_cards_of_57_quantities() -> None:
    assert len(DECK) == 57
    assert sorted({e.card for e in DECK}) == list(range(1, 16))
    assert len(BY_NAME) == 57  # one parameter each
    # Every quantity is taken by the FMU that uses it; what both use is shared.
    assert set(SHARED) == {e.name for e in DECK if e.users == BOTH}
    assert {"spin", "mu", "configuration", "wheel_pivot_radius"} <= set(SHARED)
    for user, component in ((TRAIN, GearTrain), (VERGE, VergeEscapement)):
        declared = {v.name: v for v in component.variables("parameter")}
        for v in deck_variables(user):
            assert declared[v.name] == v
            entry = BY_NAME.get(v.name)
            if entry is not None:
                assert v.design and v.description.endswith(f"[SANDA2V: {entry.symbol}]")


def test_the_defaults_are_the_m739_deck() -> None:
    for e in DECK:
        if e.field == "rpm":
            assert e.default() == M739.omega
        else:
            assert e.default() == getattr(M739, e.field), e.name


def test_the_design_file_in_source_units_gives_the_m739_values_to_the_bit() -> None:
    cards = tomllib.loads(DESIGN_FILE.read_text())["design"]
    values = {n: v for card in cards.values() if isinstance(card, dict) for n, v in card.items()}
    assert set(values) == set(BY_NAME)
    for name, text in values.items():
        e = BY_NAME[name]
        si = to_si(text, e.unit, exact=True) if isinstance(text, str) else text
        if name == "spin":  # 30000 rpm: what the M739 scene has always run at
            assert si == pytest.approx(M739.omega, rel=1e-15)
        else:
            assert si == e.default(), name
    assert data_from({n: to_si(t, BY_NAME[n].unit, True) for n, t in values.items()}) == M739.with_(
        rpm=data_from({"spin": to_si("30000 rpm", "rad/s")}).rpm
    )


def test_the_m739_breaks_no_rule() -> None:
    assert violations(M739) == []


def _in(x: float) -> float:
    return x * INCH


#: rule -> (changes of the M739 deck, texts the message names: quantities and values).
BROKEN = {
    "configuration": ({"config": 3}, ["CONFIG = 3", "expected 1 or 2"]),
    "pivot triangle": ({"r2": _in(0.8)}, ["R2 = 0.80000 in", "|R1 - R2| < CAPRP1 + RP2"]),
    "involute base radius": (
        {"rb1_cap": _in(0.37)},
        ["CAPRB1 = 0.37000 in (gear1_base_radius)", "CAPRP1 cos(THETA1) = 0.37588 in"],
    ),
    "outside radius beyond the base circle": (
        {"ro3": _in(0.03)},
        ["RO3 = 0.03000 in", "RB3 = 0.03759 in", "expected RO3 > RB3"],
    ),
    "pitch radii in the tooth ratio": ({"ng1": 65}, ["CAPRP1/RP2 = 7.11077", "NG1/NP2"]),
    "equal base pitch": ({"ng1": 65}, ["2 pi CAPRB1/NG1", "2 pi RB2/NP2"]),
    "contact on the involute": ({"ro2": _in(0.2)}, ["mesh 1", "interference"]),
    "contact ratio": ({"ro1_cap": _in(0.43)}, ["mesh 1: contact ratio = 1.", "0.95 to 1.05"]),
    "mesh start": ({"j2": 1.5}, ["J2 = 1.5", "expected 0 to 1"]),
    "arming angle": ({"phi_cut": -1.0 * DEG}, ["PHICUTD = -1.000 deg"]),
    "pallet pivot triangle": (
        {"a": _in(0.001)},
        ["A = 0.00100 in (center_distance)", "|R3 - R4| < A < R3 + R4"],
    ),
    "contact loop": ({"a": _in(0.3)}, ["A = 0.30000 in", "|B - C| < A < B + C"]),
    "entrance face angle": (
        {"lam": 95.0 * DEG},
        ["ALPHEN = 43.5352 deg", "90 deg - LAMBDA/2 = 42.5000 deg"],
    ),
    "exit face angle": ({"alpha_ex": 50.0 * DEG}, ["eta = LAMBDA/2 - ALPHEX = -3.5350 deg"]),
    "teeth spanned": ({"nt": 11}, ["NT = 11, N = 22", "1 <= NT < N/2"]),
    "start on the entrance face": ({"phi_start": 160.0 * DEG}, ["PHID = 160.000 deg", "g > 0"]),
    "escapement function": (
        {"a": _in(0.25)},
        ["NT x Delta = 4 x 16.3636 deg", "past the exit face's end", "A = 0.25000 in"],
    ),
}


@pytest.mark.parametrize("rule", sorted(BROKEN))
def test_each_rule_is_refused_with_its_quantities(rule: str) -> None:
    changes, texts = BROKEN[rule]
    found = [str(v) for v in violations(M739.with_(**changes)) if v.rule == rule]
    assert found, f"{rule} not refused"
    message = found[0]
    assert message.startswith(f"design rule '{rule}' broken: ")
    for text in texts:
        assert text in message, (text, message)


def test_fmu_initialization_refuses_a_broken_design_and_can_be_told_not_to() -> None:
    with pytest.raises(DesignError, match="'involute base radius'.*CAPRB1 = 0.37000 in"):
        GearTrain(gear1_base_radius=_in(0.37)).initialize(0.0)
    with pytest.raises(DesignError, match="'escapement function'"):
        VergeEscapement(center_distance=_in(0.25)).initialize(0.0)
    VergeEscapement(center_distance=_in(0.25), check_design=0).initialize(0.0)
    # A quantity the other FMU takes is not checked where it is not taken.
    VergeEscapement(center_distance=_in(0.226)).initialize(0.0)


def test_a_wheel_that_skips_teeth_ends_the_reference_run() -> None:
    # A = 0.25 in (inside the old declared range): the tooth leaves the entrance face
    # beyond the exit face's end, and the wheel runs through the verge untouched.
    result = run_m739(data=M739.with_(a=_in(0.25)), t_stop=0.01)
    assert not result.armed and result.impacts == 0
    assert result.reason.startswith("the escapement skips teeth: at t = 0.000694")
    assert math.isclose(result.t_end, 6.94e-4, rel_tol=1e-2)


def test_the_design_page_tabulates_every_quantity() -> None:
    page = (Path(__file__).resolve().parents[2] / "docs" / "designs.md").read_text()
    for e in DECK:
        assert f"| {e.card} | {e.symbol} | `{e.name}` |" in page, e.name
