"""The indicator families: one object each, read by assess, the fused pass and the registry.

The walk-through of the docs (``docs/how-to/extending.md``, "Adding a risk indicator")
runs here as printed: a toy family registered, computed by ``assess`` with its own
option keyword, by ``assess_fused`` with numpy, listed by the registry, refused by the
compiled plan, removed again. The compiled pass's parameter positions are derived from
the families' parameter names.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from heritage_bayes.climate import risk
from heritage_bayes.climate.risk import _fused
from heritage_bayes.climate.risk.fused import fused_plan
from heritage_bayes.climate.risk.indicators import FAMILIES, LAYOUT
from heritage_bayes.climate.risk.registry import INDICATORS, indicator_info, register
from heritage_bayes.errors import InputError

DOC = Path(__file__).resolve().parents[1] / "docs" / "how-to" / "extending.md"


def _section_blocks() -> list[str]:
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## Adding a risk indicator", 1)[1].split("\n## ", 1)[0]
    return re.findall(r'```python exec="on"[^\n]*\n(.*?)```', section, re.S)


def test_the_docs_walk_through_runs_and_leaves_no_trace(capsys):
    before = ([f.name for f in FAMILIES], dict(INDICATORS), dict(risk.INDICATOR_GROUPS))
    blocks = _section_blocks()
    assert len(blocks) == 4
    ns: dict = {}
    exec(compile("\n".join(blocks[:2]), str(DOC), "exec"), ns)
    out = capsys.readouterr().out
    assert "salt_cycles" in out and "Salt crystallisation cycles [1/year]" in out
    assert "True [" in out and out.rstrip().endswith("got 120.0")
    T, RH = ns["T"], ns["RH"]
    # registered: with its option keyword, a rating-free row, refused by the compiled plan
    table = risk.assess(T[0], RH[0], indicators=["salt"], salt={"drh": 69.0})
    assert table["indicator"].tolist() == ["salt_cycles"] and table["rating"][0] == ""
    assert "salt_cycles" not in fused_plan(8760).columns
    with pytest.raises(InputError, match="no compiled pass"):
        fused_plan(8760, indicators=["salt"])
    with pytest.raises(InputError, match="clashes"):
        register(ns["SALT"])
    # a projection offers it (numpy on the kept series): a year of weather, one per-year value
    exec(compile(blocks[2], str(DOC), "exec"), ns)
    case = ns["case"]
    assert list(case.predictive.columns)[-1] == "salt_cycles"
    assert case.annual_names[-1] == "salt_cycles"
    np.testing.assert_array_equal(case.annual_predictive[:, 0, -1], case.predictive["salt_cycles"])
    exec(compile(blocks[3], str(DOC), "exec"), ns)
    after = ([f.name for f in FAMILIES], dict(INDICATORS), dict(risk.INDICATOR_GROUPS))
    assert after == before
    with pytest.raises(InputError, match="unknown option group"):
        risk.assess(T[0], RH[0], salt={"drh": 69.0})
    with pytest.raises(InputError, match="unknown indicator"):
        indicator_info("salt_cycles")


def test_kernel_positions_follow_the_families_parameter_names():
    compiled = [f for f in FAMILIES if f.compiled]
    assert LAYOUT.ints[: len(compiled)] == tuple(f.name for f in compiled)
    assert len(set(LAYOUT.ints)) == len(LAYOUT.ints)
    assert len(set(LAYOUT.floats)) == len(LAYOUT.floats)
    assert _fused.I_MOULD == LAYOUT.i("mould")
    assert _fused.F_LIMC == LAYOUT.f("mould.lim_c")
    # the VTT parameters the fused pass slices are contiguous, in _vtt's order
    vtt = [LAYOUT.f(f"mould.{p}") for p in ("k1_lo", "k1_hi", "A", "B", "C", "RH_min",
                                             "C_mat", "W", "SQ")]  # fmt: skip
    assert vtt == list(range(_fused.F_VTT, _fused.F_VTT + 9))
    # every parameter a plan sets is declared by its family
    plan = fused_plan(8760, ashrae={"T_setpoint": 15.0, "RH_setpoint": 50.0})
    _, fpar, ipar, _, _ = plan.arrays
    assert ipar.size == len(LAYOUT.ints) and fpar.size == len(LAYOUT.floats)
    assert fpar[LAYOUT.f("ashrae.T_setpoint")] == 15.0


def test_every_column_has_a_registry_entry_and_ratings_come_from_it():
    t = np.arange(8760)
    T = 12 + 6 * np.sin(2 * np.pi * t / 8760)
    RH = 60 + 8 * np.sin(2 * np.pi * t / 24)
    table = risk.assess(T, RH).set_index("indicator")
    for name in table.index:
        info = indicator_info(name)
        assert table.loc[name, "unit"] == info.unit
    assert table.loc["twpi", "rating"] == indicator_info("twpi").rating(table.loc["twpi", "value"])
    assert indicator_info("time_of_wetness").rating(2500.0) == "τ3"
    assert indicator_info("time_of_wetness").rating(6000.0) == "τ5"
    assert "rating" not in indicator_info("twpi").as_dict()
