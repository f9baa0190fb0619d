"""Derived identifiable quantities and the structural identifiability check.

Tolerances follow from the numerics: the Jacobian is analytic (exact network-matrix
derivatives), so structurally zero singular values are at rounding level (~1e-16 of the
largest) while identifiable ones are >= ~1e-2 at the parameter sets used here; eigenvalues
and gains from ``eigh`` of a symmetric 3x3 agree with ``numpy.linalg.eigvals``/``solve``
to ~1e-13 relative; exact ZOH simulation converges to the steady state as exp(-t/tau).
"""

import doctest
import json

import numpy as np
import pytest
from scipy.optimize import least_squares

import heritage_bayes as hb
from heritage_bayes.rc import Link, Network, Node, RCModel, Source
from heritage_bayes.rc import identify as ident
from heritage_bayes.rc.identify import (
    constant_contributions,
    derived_quantities,
    derived_units,
    static_gains,
    structural_identifiability,
    time_constants,
)

P4A = dict(
    Cw=5e8,
    Ci=2e6,
    Cint=5e7,
    Gw=400.0,
    Gi=600.0,
    Gint=300.0,
    Gfast=100.0,
    Gf=20.0,
    fI_N=0.5,
    fI_E=1.0,
    fI_S=2.0,
    fI_W=1.0,
    fsol=0.0,
)
PHYG = dict(Cw=5e-3, Ci=1e-4, Gw=1e-8, Gi=5e-8, Gfast=2e-8)
PHYGF = {**PHYG, "Gf": 1e-8, "Pf": 1200.0}
P1C = dict(Ci=2e6, Ge=150.0, Gf=20.0, fI_N=0.5, fI_E=1.0, fI_S=2.0, fI_W=1.0)

LOG_KINDS = ("capacity", "conductance", "gain")


def _point(m):
    """A plausible parameter set for any catalogue model."""
    base = {**P4A, **P1C, "Ci": P4A["Ci"]} if m.domain == "thermal" else PHYGF
    return {n: base[n] for n in m.parameter_names}


def _batch(m, K, seed=0):
    rng = np.random.default_rng(seed)
    p = _point(m)
    out = {}
    for info in m.parameters:
        if info.kind == "fraction":
            out[info.name] = rng.uniform(0, 1, K)
        elif info.kind == "constant":
            out[info.name] = p[info.name] + rng.normal(0, 100, K)
        else:
            out[info.name] = p[info.name] * np.exp(rng.normal(0, 0.5, K))
    return out


def _scaled(m, p, factor):
    kinds = {i.name: i.kind for i in m.parameters}
    return {k: v * factor if kinds[k] in LOG_KINDS else v for k, v in p.items()}


def _scale_vector(m):
    s = np.array([1.0 if i.kind in LOG_KINDS else 0.0 for i in m.parameters])
    return s / np.linalg.norm(s)


def _raw_null_space(J, rtol=ident.DEFAULT_RTOL):
    """Null space straight from the SVD of the column-scaled Jacobian (θ coordinates)."""
    c = np.linalg.norm(J, axis=0)
    _, s, Vt = np.linalg.svd(J / c)
    rank = int(np.sum(s > rtol * s[0]))
    N = Vt[rank:].T / c[:, None]
    return rank, np.linalg.qr(N)[0]


# ------------------------------------------------------------------ derived quantities
@pytest.mark.parametrize("name", ["thermal_4a", "thermal_2c", "hygric_2c", "hygric_2c_fixed"])
def test_time_constants_and_gains_match_numpy(name):
    m = hb.model(name)
    batch = _batch(m, 6, seed=1)
    tau = time_constants(m, batch)
    g = static_gains(m, batch)
    assert tau.shape == (6, m.n_states) and g.shape == (6, m.n_outputs, m.n_inputs)
    A, B, C, _ = m.state_space(batch)
    for k in range(6):
        ref = np.sort(-1.0 / np.linalg.eigvals(A[k]).real)[::-1]
        np.testing.assert_allclose(tau[k], ref, rtol=1e-10)
        np.testing.assert_allclose(g[k], -C @ np.linalg.solve(A[k], B[k]), rtol=1e-10, atol=1e-14)
    assert np.all(np.diff(tau, axis=1) <= 0)  # slowest first


def test_constant_contribution_matches_offset():
    m = hb.model("hygric_2c_fixed")
    A, _, C, _ = m.state_space(PHYGF)
    e = m.offset(PHYGF)
    yc = constant_contributions(m, PHYGF)
    assert yc.shape == (1, 1)
    np.testing.assert_allclose(yc[:, 0], -C @ np.linalg.solve(A, e), rtol=1e-12)
    # networks without constants: an empty last axis
    assert constant_contributions(hb.model("thermal_4a"), P4A).shape == (1, 0)


@pytest.mark.parametrize(
    ("name", "params", "u"),
    [
        ("thermal_4a", P4A, [5.0, 100.0, 50.0, 300.0, 20.0, 11.0]),
        ("hygric_2c_fixed", PHYGF, [900.0]),
        ("hygric_2c", PHYG, [900.0]),
    ],
)
def test_long_constant_input_simulation_converges_to_static_gains(name, params, u):
    m = hb.model(name)
    u = np.asarray(u)
    dt = 3600.0
    tau_max = time_constants(m, params)[0]
    N = int(np.ceil(40 * tau_max / dt))  # transient exp(-40) ~ 4e-18 of the start
    y = hb.simulate(m, params, np.tile(u, (N, 1)), dt, x0=np.zeros(m.n_states))
    expect = static_gains(m, params) @ u + constant_contributions(m, params).sum(axis=1)
    np.testing.assert_allclose(y[-1], expect, rtol=1e-9)
    assert not np.allclose(y[0], expect)  # it did start away from the steady state


@pytest.mark.parametrize(
    ("name", "params"),
    [("thermal_4a", P4A), ("thermal_1c", P1C), ("hygric_2c", PHYG), ("hygric_2c_fixed", PHYGF)],
)
def test_derived_quantities_are_invariant_under_the_scale_direction(name, params):
    m = hb.model(name)
    d1 = derived_quantities(m, params)
    d7 = derived_quantities(m, _scaled(m, params, 7.0))
    assert list(d1) == list(d7)
    for k in d1:
        assert d7[k] == pytest.approx(d1[k], rel=1e-12, abs=1e-15), k
    # ... and actually change along a direction that is not a null direction
    d_other = derived_quantities(m, {**params, "Ci": params["Ci"] * 7})
    assert any(abs(d_other[k] - d1[k]) > 1e-6 * abs(d1[k]) for k in d1)


def test_derived_names_units_and_order():
    m = hb.model("thermal_4a", heating=True)
    d = derived_quantities(m, P4A)
    u = derived_units(m)
    assert list(d) == list(u)
    assert list(d)[:3] == ["tau_1_h", "tau_2_h", "tau_3_h"]
    assert u["tau_1_h"] == "h"
    assert u["gain_Ti_Te"] == "-" and u["gain_Ti_Tf"] == "-"
    assert u["gain_Ti_I_S"] == "K/(W/m²)"
    assert u["gain_Ti_Ph"] == "K/W"
    assert [k for k in d if k.startswith("gain_")] == [f"gain_Ti_{i}" for i in m.input_names]
    assert d["tau_1_h"] == pytest.approx(time_constants(m, P4A)[0] / 3600, rel=1e-14)
    assert all(isinstance(v, float) for v in d.values())
    mh = hb.model("hygric_2c_fixed")
    dh = derived_quantities(mh, PHYGF)
    assert list(dh) == ["tau_1_h", "tau_2_h", "gain_Pi_Pe", "offset_Pi_Pf"]
    assert derived_units(mh) == {
        "tau_1_h": "h",
        "tau_2_h": "h",
        "gain_Pi_Pe": "-",
        "offset_Pi_Pf": "Pa",
    }
    # steady state: gain * Pe + offset; potential gains of a pure conduction network
    # sum to one with the constant's share
    A, _, _, _ = mh.state_space(PHYGF)
    share_f = dh["offset_Pi_Pf"] / PHYGF["Pf"]
    assert dh["gain_Pi_Pe"] + share_f == pytest.approx(1.0, rel=1e-12)


def test_batch_equals_single_and_array_input():
    m = hb.model("thermal_4a")
    batch = _batch(m, 5, seed=2)
    db = derived_quantities(m, batch)
    P, _ = m.param_array(batch)
    da = derived_quantities(m, P)
    for k in range(5):
        single = {n: v[k] for n, v in batch.items()}
        ds = derived_quantities(m, single)
        dr = derived_quantities(m, P[k])  # a (P,) array is one parameter set
        for name in db:
            assert db[name].shape == (5,)
            assert db[name][k] == pytest.approx(ds[name], rel=1e-13)
            assert dr[name] == ds[name] and da[name][k] == db[name][k]
    assert time_constants(m, P4A).shape == (3,)
    assert static_gains(m, P4A).shape == (1, 6)
    with pytest.raises(ValueError, match=r"expected a mapping name -> value, a \(13,\) array"):
        time_constants(m, np.ones(4))


def test_inadmissible_rows_give_nan_not_an_exception():
    m = hb.model("thermal_4a")
    P, _ = m.param_array(_batch(m, 4, seed=3))
    P[1, 0] = -1.0  # negative capacity
    P[2, 12] = 1.5  # fraction above 1
    d = derived_quantities(m, P)
    for v in d.values():
        assert np.isnan(v[1]) and np.isnan(v[2])
        assert np.isfinite(v[0]) and np.isfinite(v[3])


def test_large_batch_is_vectorised(monkeypatch):
    """K = 10,000 draws: the work is batched linear algebra, not a loop over draws."""
    m = hb.model("hygric_2c_fixed")
    calls = []
    orig = type(m).network_matrices

    def counting(self, P):
        calls.append(P.shape[0])
        return orig(self, P)

    monkeypatch.setattr(type(m), "network_matrices", counting)
    counts = {}
    for K in (10, 10_000):
        calls.clear()
        d = derived_quantities(m, _batch(m, K, seed=4))
        counts[K] = list(calls)
        assert all(v.shape == (K,) and np.all(np.isfinite(v)) for v in d.values())
    # the same few whole-batch calls, whatever K
    assert len(counts[10]) == len(counts[10_000]) == 2  # modal form + the constant
    assert set(counts[10_000]) == {10_000}
    m4 = hb.model("thermal_4a")
    d4 = derived_quantities(m4, _batch(m4, 10_000, seed=5))
    assert len(d4) == 3 + 6 and all(v.shape == (10_000,) for v in d4.values())


# ------------------------------------------------------------ structural identifiability
SCALE_ONLY = [
    ("thermal_4a", {}),
    ("thermal_4a", {"ground": False}),
    ("thermal_4a", {"surfaces": ("S",)}),
    ("thermal_4a_nosolar", {}),
    ("thermal_2c", {}),
    ("thermal_1c", {}),
    ("hygric_1c", {}),
]


@pytest.mark.parametrize(("name", "opts"), SCALE_ONLY)
def test_unheated_models_have_exactly_the_scale_direction(name, opts):
    m = hb.model(name, **opts)
    p = _point(m)
    r = structural_identifiability(m, p)
    P = len(m.parameter_names)
    assert r.rank == P - 1 and r.n_null == 1
    assert [d.label for d in r.directions] == ["overall scale"]
    assert r.directions[0].is_scale and r.scale_reference == "Ci"
    # the raw SVD null space (not the labelled template) is the scale vector
    rank, N = _raw_null_space(r.jacobian)
    assert rank == P - 1
    assert abs(N[:, 0] @ _scale_vector(m)) == pytest.approx(1.0, abs=1e-8)
    v = np.array([r.directions[0].vector[n] for n in m.parameter_names])
    np.testing.assert_allclose(v, _scale_vector(m), atol=1e-14)
    # a clear-cut rank decision: rounding-level zero, identifiable part far above rtol
    s = r.singular_values
    assert s[-1] <= 1e-13 * s[0] and s[-2] >= 1e-4 * s[0]
    assert r.gap > 1e9
    # flags: every C, G, gain is on the scale direction; fractions are not; all are
    # identifiable once the scale is pinned through Ci
    kinds = {i.name: i.kind for i in m.parameters}
    assert r.identifiable == {n: kinds[n] not in LOG_KINDS for n in m.parameter_names}
    assert all(r.identifiable_given_scale.values())
    text = r.directions[0].description
    assert text.startswith("scaling ") and "Ci" in text and "room air volume" in text
    assert set(r.directions[0].pinned_by) == {n for n in kinds if kinds[n] in LOG_KINDS}


def test_thermal_4a_description_reads_as_specified():
    r = structural_identifiability(hb.model("thermal_4a"), P4A)
    text = r.directions[0].description
    assert text.startswith(
        "scaling Cw, Ci, Cint, Gw, Gi, Gint, Gfast, Gf, fI_N, fI_E, fI_S and fI_W together "
        "by the same factor (with fsol unchanged) leaves the output unchanged"
    )
    assert "known heat input" in text
    assert "rank 12 of 13" in r.summary()


def test_known_heat_input_pins_the_scale():
    m = hb.model("thermal_4a", heating=True)
    r = structural_identifiability(m, P4A)
    assert r.rank == len(m.parameter_names) == 13
    assert r.is_identifiable and r.directions == () and r.scale_reference is None
    assert all(r.identifiable.values())
    assert np.isfinite(r.condition_number) and r.condition_number < 1e3
    assert r.gap is None
    assert "all identifiable" in r.summary()


def _tf_coefficients(m, p):
    """Characteristic polynomial and numerator of Pe -> Pi, plus the constant offset."""
    A, B, C, _ = m.state_space(p)
    den = np.poly(A)
    num = np.poly(A - np.outer(B[:, 0], C[0])) - den  # C adj(sI-A) B
    out = np.concatenate([den[1:], num[1:]])
    return np.append(out, constant_contributions(m, p).sum()) if "Pf" in p else out


def _other_member(m, p, gw_factor):
    """A parameter set with the same Ci, Gfast and input-output behaviour as p but a
    different Gw: solve for the remaining parameters (not a scaling of p)."""
    target = _tf_coefficients(m, p)
    free = [n for n in m.parameter_names if n not in ("Ci", "Gfast", "Gw")]

    def build(x):
        q = dict(p)
        q["Gw"] = p["Gw"] * gw_factor
        for n, v in zip(free, x, strict=True):
            q[n] = np.exp(v) if n != "Pf" else v
        return q

    def resid(x):
        return (_tf_coefficients(m, build(x)) - target) / np.abs(target)

    x0 = [np.log(p[n]) if n != "Pf" else p[n] for n in free]
    sol = least_squares(resid, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-10
    return build(sol.x)


@pytest.mark.parametrize(("name", "params"), [("hygric_2c", PHYG), ("hygric_2c_fixed", PHYGF)])
def test_two_node_hygric_models_have_a_second_null_direction(name, params):
    """A single potential boundary (Pe) fixes the static gain at 1: the transfer function
    has 3 free coefficients for 4 scale-free parameters, so even with Ci known the buffer
    (Cw, Gw, and Gf for the fixed-node model) is not identifiable."""
    m = hb.model(name)
    r = structural_identifiability(m, params)
    P = len(m.parameter_names)
    assert r.rank == P - 2
    assert [d.label for d in r.directions] == ["overall scale", "direction 2"]
    rank, N = _raw_null_space(r.jacobian)
    assert rank == P - 2
    s_hat = _scale_vector(m)
    assert np.linalg.norm(N.T @ s_hat) == pytest.approx(1.0, abs=1e-8)  # scale in it
    d2 = r.directions[1]
    v2 = np.array([d2.vector[n] for n in m.parameter_names])
    assert np.linalg.norm(N.T @ v2) == pytest.approx(1.0, abs=1e-8)
    assert d2.vector["Ci"] == 0.0 and abs(d2.vector["Gfast"]) < 1e-10
    assert d2.pinned_by[:2] == ("Gw", "Cw")
    assert "even with the overall scale pinned through Ci" in d2.description
    # an explicit, finite counterexample: a different buffer with the same output
    q = _other_member(m, params, 2.0)
    assert q["Cw"] / params["Cw"] != pytest.approx(2.0, rel=1e-3)  # not a scaling
    rng = np.random.default_rng(7)
    U = 1000 + np.cumsum(rng.normal(0, 20, (3000, 1)), axis=0)
    y1, y2 = hb.simulate(m, params, U), hb.simulate(m, q, U)
    assert np.max(np.abs(y2 - y1)) <= 1e-8 * np.max(np.abs(y1))
    d_p, d_q = derived_quantities(m, params), derived_quantities(m, q)
    for k in d_p:
        assert d_q[k] == pytest.approx(d_p[k], rel=1e-8)
    # and the curve's tangent at p is the reported direction
    eps = 1e-4
    q_eps = _other_member(m, params, np.exp(eps))
    names = m.parameter_names
    t = np.array([(np.log(q_eps[n] / params[n]) if n != "Pf" else 0.0) / eps for n in names])
    t /= np.linalg.norm(t)
    assert abs(t @ v2) == pytest.approx(1.0, abs=1e-3)


def test_jacobian_matches_finite_differences_of_the_frequency_response():
    m = hb.model("hygric_2c_fixed")
    p = {**PHYGF, "Pf": 1500.0}
    r = structural_identifiability(m, p, n_freq=12)
    names = m.parameter_names
    kinds = [i.kind for i in m.parameters]
    omega = r.omega

    def observables(q):
        A, B, C, _ = m.state_space(q)
        H = np.array([C @ np.linalg.solve(1j * w * np.eye(2) - A, B) for w in omega])
        yc = (-C @ np.linalg.solve(A, m.offset(q)))[0]
        return H[:, 0, 0], yc

    H0, _ = observables(p)
    h = 1e-5
    cols = []
    for n, k in zip(names, kinds, strict=True):
        up, dn = dict(p), dict(p)
        if k in LOG_KINDS:
            up[n], dn[n] = p[n] * np.exp(h), p[n] * np.exp(-h)
        else:
            up[n], dn[n] = p[n] + h * max(abs(p[n]), 1.0), p[n] - h * max(abs(p[n]), 1.0)
        (Hu, yu), (Hd, yd) = observables(up), observables(dn)
        dH = (Hu - Hd) / (2 * h) / np.abs(H0)
        g_unit = p["Gf"] * np.linalg.solve(-m.state_space(p)[0], [0, 1 / p["Ci"]])[1]
        dy = (yu - yd) / (2 * h) * np.sqrt(2 * len(omega) - 1) / (g_unit * abs(p["Pf"]))
        cols.append(np.concatenate([dH.real, dH.imag[1:], [dy]]))
    J_fd = np.column_stack(cols)
    assert r.jacobian.shape == J_fd.shape
    # central differences: truncation ~h^2, rounding ~1e-16/h: agreement to ~1e-8
    np.testing.assert_allclose(r.jacobian, J_fd, rtol=1e-6, atol=1e-8 * np.abs(J_fd).max())


def test_result_is_invariant_under_scaling_the_point_and_stable_over_dt():
    m = hb.model("thermal_4a")
    r1 = structural_identifiability(m, P4A)
    r7 = structural_identifiability(m, _scaled(m, P4A, 7.0))
    # relative sensitivities do not change along the scale direction
    np.testing.assert_allclose(r7.singular_values[:-1], r1.singular_values[:-1], rtol=1e-10)
    for dt in (60.0, 900.0, 86400.0):
        r = structural_identifiability(m, {**P4A, "fsol": 0.4}, dt)
        assert r.rank == 12 and r.has_scale_direction


def test_parallel_links_and_disconnected_nodes_are_described():
    net = Network(
        name="toy",
        domain="thermal",
        nodes=(Node("Ti", "Ci"), Node("Tx", "Cx")),
        links=(Link("Ti", "Te", "G1"), Link("Ti", "Te", "G2"), Link("Tx", "Te", "Gx")),
        inputs=("Te", "I_S"),
        outputs=("Ti",),
        sources=(Source("I_S", "Ti", "a"),),
    )
    m = RCModel(net)
    p = dict(Ci=1e6, Cx=1e7, G1=30.0, G2=70.0, Gx=5.0, a=2.0)
    r = structural_identifiability(m, p)
    # Ci, G1 + G2, a: two ratios identifiable; Cx, Gx: no influence at all
    assert r.rank == 2
    labels = [d.label for d in r.directions]
    assert labels[0] == "overall scale" and len(labels) == 4
    assert set(r.directions[0].pinned_by) == {"Ci", "G1", "G2", "a"}
    by_pin = {d.pinned_by: d for d in r.directions[1:]}
    assert "only their sum G1 + G2 is identifiable" in by_pin[("G1", "G2")].description
    assert "Cx is not identifiable" in by_pin[("Cx",)].description
    assert "Gx is not identifiable" in by_pin[("Gx",)].description
    assert r.null_loading["Cx"] == pytest.approx(1.0) and not r.identifiable["Gx"]
    assert r.identifiable_given_scale["a"] and r.identifiable_given_scale["Ci"]
    assert not r.identifiable_given_scale["G1"]


def test_to_dict_is_json_and_complete():
    r = structural_identifiability(hb.model("hygric_2c_fixed"), PHYGF)
    d = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert d["rank"] == 5 and d["n_params"] == 7 and d["n_null"] == 2
    assert d["has_scale_direction"] and d["scale_reference"] == "Ci"
    assert d["condition_number"] is None or d["condition_number"] > 1e12
    assert d["method"]["omega_max"] == pytest.approx(np.pi / 3600.0)
    assert d["method"]["omega_min"] == pytest.approx(2 * np.pi / ident.DEFAULT_LONGEST_PERIOD)
    assert [x["label"] for x in d["null_directions"]] == ["overall scale", "direction 2"]
    assert d["parameters"]["Pf"]["identifiable"] is True
    assert d["transforms"] == {
        "Cw": "log",
        "Ci": "log",
        "Gw": "log",
        "Gi": "log",
        "Gfast": "log",
        "Gf": "log",
        "Pf": "relative",
    }
    assert len(d["singular_values"]) == 7
    assert r.null_space.shape == (7, 2)


def test_bad_calls_are_rejected_with_messages():
    m = hb.model("thermal_4a")
    with pytest.raises(ValueError, match="one parameter set"):
        structural_identifiability(m, {**P4A, "Ci": np.array([1e6, 2e6])})
    with pytest.raises(ValueError, match=r"conductance Gf must be > 0.*got 0"):
        structural_identifiability(m, {**P4A, "Gf": 0.0})
    with pytest.raises(ValueError, match="capacity Ci must be > 0"):
        structural_identifiability(m, {**P4A, "Ci": -1.0})
    with pytest.raises(ValueError, match="n_freq must be an integer >= 2"):
        structural_identifiability(m, P4A, n_freq=1)
    with pytest.raises(ValueError, match="longest_period must exceed the Nyquist period"):
        structural_identifiability(m, P4A, dt=86400.0, longest_period=86400.0)
    with pytest.raises(ValueError, match=r"rtol must be a number in \(0, 1\)"):
        structural_identifiability(m, P4A, rtol=0.0)
    with pytest.raises(ValueError, match="dt must be a positive number"):
        structural_identifiability(m, P4A, dt=-1)
    with pytest.raises(TypeError):
        structural_identifiability(m, P4A, tolerance=1e-3)  # unknown keyword


def test_docstring_examples_run():
    res = doctest.testmod(ident, raise_on_error=False)
    assert res.attempted >= 5 and res.failed == 0


def test_fixing_a_known_parameter_removes_the_scale_direction():
    m = hb.model("thermal_4a")
    r = structural_identifiability(m, P4A, fixed=("Ci",))
    assert r.parameter_names == tuple(n for n in m.parameter_names if n != "Ci")
    assert r.fixed == ("Ci",) and r.point["Ci"] == P4A["Ci"]
    assert r.rank == 12 and r.is_identifiable
    # in the hygric model 3 the buffer direction survives a known air capacity
    mh = hb.model("hygric_2c")
    rh = structural_identifiability(mh, PHYG, fixed=["Ci"])
    assert rh.rank == 3 and len(rh.directions) == 1
    d = rh.directions[0]
    assert not d.is_scale and d.pinned_by[:2] == ("Gw", "Cw")
    assert not d.description.startswith("even with")
    # ... and knowing Cw as well makes the rest identifiable
    assert structural_identifiability(mh, PHYG, fixed=["Ci", "Cw"]).is_identifiable
    # a fixed conductance may sit at 0 (its log is not needed)
    r0 = structural_identifiability(m, {**P4A, "Gf": 0.0}, fixed=["Gf"])
    assert r0.rank == 11 and r0.has_scale_direction
    with pytest.raises(ValueError, match=r"fixed: unknown parameter\(s\) \['Cx'\]"):
        structural_identifiability(m, P4A, fixed=["Cx"])
    with pytest.raises(ValueError, match="every parameter is fixed"):
        structural_identifiability(mh, PHYG, fixed=mh.parameter_names)
