"""RC networks, catalogue, exact discretization and simulation against scipy references."""

import numpy as np
import pandas as pd
import pytest
from scipy import signal
from scipy.linalg import expm

import heritage_bayes as hb
from heritage_bayes.rc import Link, Network, Node, RCModel, Source, iter_simulate, modal_form

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


def _inputs(m, N, seed=0):
    rng = np.random.default_rng(seed)
    cols = []
    for name in m.input_names:
        if name.startswith("I_"):
            cols.append(
                np.clip(300 * np.sin(np.arange(N) * 2 * np.pi / 24), 0, None)
                * rng.uniform(0.5, 1.0, N)
            )
        elif name == "Pe":
            cols.append(1000 + 300 * np.sin(np.arange(N) * 2 * np.pi / 8760) + rng.normal(0, 50, N))
        else:
            cols.append(
                10
                + 8 * np.sin(np.arange(N) * 2 * np.pi / 8760)
                + 3 * np.sin(np.arange(N) * 2 * np.pi / 24)
                + rng.normal(0, 1, N)
            )
    return np.column_stack(cols)


def _zoh_expm(A, B, dt):
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = expm(M * dt)
    return E[:n, :n], E[:n, n:]


def test_thermal_4a_matches_paper_equations():
    m = hb.model("thermal_4a")
    assert m.parameter_names[:8] == ("Cw", "Ci", "Cint", "Gw", "Gi", "Gint", "Gfast", "Gf")
    assert m.input_names == ("Te", "I_N", "I_E", "I_S", "I_W", "Tf")
    assert m.state_names == ("Tw", "Ti", "Tint")
    assert m.output_names == ("Ti",)
    A, B, C, D = m.state_space(P4A)
    p = P4A
    Aref = np.array(
        [
            [(-p["Gw"] - p["Gi"]) / p["Cw"], p["Gi"] / p["Cw"], 0],
            [
                p["Gi"] / p["Ci"],
                (-p["Gi"] - p["Gf"] - p["Gint"] - p["Gfast"]) / p["Ci"],
                p["Gint"] / p["Ci"],
            ],
            [0, p["Gint"] / p["Cint"], -p["Gint"] / p["Cint"]],
        ]
    )
    fI = [p["fI_N"], p["fI_E"], p["fI_S"], p["fI_W"]]
    # with fsol = 0 all solar heats the air node: the paper's printed B matrix
    Bref = np.array(
        [
            [p["Gw"] / p["Cw"], 0, 0, 0, 0, 0],
            [p["Gfast"] / p["Ci"], *(f / p["Ci"] for f in fI), p["Gf"] / p["Ci"]],
            [0, 0, 0, 0, 0, 0],
        ]
    )
    np.testing.assert_allclose(A, Aref, rtol=1e-14, atol=0)
    np.testing.assert_allclose(B, Bref, rtol=1e-14, atol=0)
    np.testing.assert_array_equal(C, [[0, 1, 0]])
    np.testing.assert_array_equal(D, np.zeros((1, 6)))
    # the split fraction sends fsol of the solar gain to the interior mass
    _, B2, _, _ = m.state_space({**P4A, "fsol": 0.25})
    np.testing.assert_allclose(B2[1, 1:5], 0.75 * np.array(fI) / p["Ci"], rtol=1e-14)
    np.testing.assert_allclose(B2[2, 1:5], 0.25 * np.array(fI) / p["Cint"], rtol=1e-14)


def test_hygric_model_3_matches_paper_and_fixed_node():
    m = hb.model("hygric_2c")
    assert m.parameter_names == ("Cw", "Ci", "Gw", "Gi", "Gfast")
    assert m.input_names == ("Pe",) and m.output_names == ("Pi",)
    A, B, C, D = m.state_space(PHYG)
    p = PHYG
    np.testing.assert_allclose(
        A,
        [
            [(-p["Gw"] - p["Gi"]) / p["Cw"], p["Gi"] / p["Cw"]],
            [p["Gi"] / p["Ci"], (-p["Gi"] - p["Gfast"]) / p["Ci"]],
        ],
        rtol=1e-14,
    )
    np.testing.assert_allclose(B, [[p["Gw"] / p["Cw"]], [p["Gfast"] / p["Ci"]]], rtol=1e-14)
    np.testing.assert_array_equal(C, [[0, 1]])
    mf = hb.model("hygric_2c_fixed")
    assert mf.parameter_names == ("Cw", "Ci", "Gw", "Gi", "Gfast", "Gf", "Pf")
    pf = {**PHYG, "Gf": 1e-8, "Pf": 1500.0}
    Af, _, _, _ = mf.state_space(pf)
    assert Af[1, 1] == pytest.approx((-p["Gi"] - p["Gfast"] - 1e-8) / p["Ci"], rel=1e-14)
    np.testing.assert_allclose(mf.offset(pf), [0.0, 1e-8 * 1500.0 / p["Ci"]], rtol=1e-14)
    # steady state with Pe constant: conductance-weighted mean of Pe and Pf, the buffer
    # path Gw-Gi acting as one series conductance to Pe
    y = hb.simulate(mf, pf, np.full((10, 1), 1000.0))
    g_series = p["Gw"] * p["Gi"] / (p["Gw"] + p["Gi"])
    g_e = g_series + p["Gfast"]
    expect = (g_e * 1000 + 1e-8 * 1500) / (g_e + 1e-8)
    np.testing.assert_allclose(y[:, 0], expect, rtol=1e-12)


@pytest.mark.parametrize("name", sorted(hb.available_models()))
def test_every_catalogue_model_compiles_and_is_stable(name):
    m = hb.model(name)
    rng = np.random.default_rng(1)
    params = {}
    for info in m.parameters:
        params[info.name] = {
            "capacity": 1e6,
            "conductance": 50.0,
            "gain": 1.0,
            "fraction": 0.3,
            "constant": 10.0,
            "sorption_capacity": 0.2,  # [kg] per unit RH
            "saturation": 0.45,
        }[info.kind] * (rng.uniform(0.5, 2) if info.kind != "fraction" else 1)
        if m.domain == "hygric" and info.kind == "capacity":
            params[info.name] = 1e-4
        if m.domain == "hygric" and info.kind == "conductance":
            params[info.name] = 1e-8
    A, B, C, D = m.state_space(params)
    assert A.shape == (m.n_states, m.n_states) and B.shape == (m.n_states, m.n_inputs)
    assert np.all(np.linalg.eigvals(A).real < 0)
    assert np.allclose(np.linalg.eigvals(A).imag, 0)
    assert len({i.unit for i in m.parameters if i.kind == "capacity"}) == 1


STIFF = [
    P4A,
    {**P4A, "fsol": 0.7},
    # time constants from seconds (tiny air capacity) to decades (heavy envelope)
    {**P4A, "Ci": 1e3, "Cw": 1e11, "Gw": 10.0, "Gfast": 100.0, "fsol": 0.3},
    {**P4A, "Cint": 1e12, "Gint": 0.5, "Gf": 1e-3},
]


@pytest.mark.parametrize("params", STIFF)
@pytest.mark.parametrize("dt", [60.0, 3600.0, 86400.0])
def test_discretization_matches_expm(params, dt):
    m = hb.model("thermal_4a")
    A, B, _, _ = m.state_space(params)
    Ad, Bd, _, _, ed = hb.discretize(m, params, dt)
    Aref, Bref = _zoh_expm(A, B, dt)
    assert np.abs(Ad - Aref).max() <= 1e-9 * np.abs(Aref).max()
    assert np.abs(Bd - Bref).max() <= 1e-9 * np.abs(Bref).max()
    np.testing.assert_array_equal(ed, 0.0)
    lam = np.sort(-np.linalg.eigvals(A).real)
    mf = modal_form(m, m.param_array(params)[0], dt)
    np.testing.assert_allclose(np.sort(mf.lam[0]), lam, rtol=1e-8)


def test_discretization_with_constant_boundary_matches_expm():
    m = hb.model("hygric_2c_fixed")
    p = {**PHYG, "Gf": 2e-9, "Pf": 1800.0}
    A, B, _, _ = m.state_space(p)
    e = m.offset(p)
    Baug = np.column_stack([B, e])
    Ad, Bd, _, _, ed = hb.discretize(m, p, 3600.0)
    Aref, Bref = _zoh_expm(A, Baug, 3600.0)
    assert np.abs(Ad - Aref).max() <= 1e-9 * np.abs(Aref).max()
    assert np.abs(np.column_stack([Bd, ed]) - Bref).max() <= 1e-9 * np.abs(Bref).max()


@pytest.mark.parametrize("params", STIFF)
def test_simulation_matches_dlsim(params):
    m = hb.model("thermal_4a")
    U = _inputs(m, 2 * 8760)
    y = hb.simulate(m, params, U, dt=3600.0)
    A, B, C, D = m.state_space(params)
    Aref, Bref = _zoh_expm(A, B, 3600.0)
    x0 = np.linalg.solve(-A, B @ U[0])
    _, yref, _ = signal.dlsim((Aref, Bref, C, D, 3600.0), U, x0=x0)
    assert y.shape == (len(U), 1)
    assert np.abs(y - yref).max() <= 1e-9 * np.abs(yref).max()


def test_batch_equals_loop_and_chunking_is_invisible():
    m = hb.model("thermal_4a")
    rng = np.random.default_rng(3)
    K = 7
    batch = {k: v * np.exp(rng.normal(0, 0.3, K)) for k, v in P4A.items() if k != "fsol"}
    batch["fsol"] = rng.uniform(0, 1, K)
    U = _inputs(m, 3000)
    Y = hb.simulate(m, batch, U)
    assert Y.shape == (K, 3000, 1)
    for k in range(K):
        yk = hb.simulate(m, {n: v[k] for n, v in batch.items()}, U)
        np.testing.assert_allclose(Y[k], yk, rtol=1e-12, atol=1e-12)
    # tiny forcing blocks and tiny parameter chunks give the same numbers
    Y2 = hb.simulate(m, batch, U, max_block=10)
    np.testing.assert_allclose(Y2, Y, rtol=1e-12, atol=1e-12)
    parts = list(iter_simulate(m, batch, U, chunk=3))
    assert [sl for sl, _ in parts] == [slice(0, 3), slice(3, 6), slice(6, 7)]
    np.testing.assert_allclose(np.concatenate([y for _, y in parts]), Y, rtol=1e-12)


def test_scalars_broadcast_in_a_batch():
    m = hb.model("hygric_2c")
    batch = {**PHYG, "Gfast": np.array([1e-8, 2e-8, 4e-8])}
    Y = hb.simulate(m, batch, _inputs(m, 500))
    assert Y.shape == (3, 500, 1)
    assert not np.allclose(Y[0], Y[2])


def test_initial_state_default_is_steady_state_and_explicit_x0():
    m = hb.model("thermal_4a")
    U = np.tile([5.0, 0, 0, 0, 0, 12.0], (100, 1))
    y = hb.simulate(m, P4A, U)
    A, B, _, _ = m.state_space(P4A)
    x_ss = np.linalg.solve(-A, B @ U[0])
    np.testing.assert_allclose(y[:, 0], x_ss[1], rtol=1e-12)
    y0 = hb.simulate(m, P4A, U, x0=[20.0, 20.0, 20.0])
    assert y0[0, 0] == pytest.approx(20.0, abs=1e-12)
    assert y0[-1, 0] < 20.0  # cools towards the outdoor/ground temperature


def test_dataframe_inputs_by_column_name():
    m = hb.model("thermal_2c")
    U = _inputs(m, 200)
    df = pd.DataFrame(U[:, ::-1], columns=list(m.input_names)[::-1])
    df["extra"] = 1.0
    p = dict(
        Cw=5e8,
        Ci=2e6,
        Gw=400.0,
        Gi=600.0,
        Gfast=100.0,
        Gf=20.0,
        fI_N=0.5,
        fI_E=1.0,
        fI_S=2.0,
        fI_W=1.0,
    )
    np.testing.assert_allclose(hb.simulate(m, p, df), hb.simulate(m, p, U), rtol=1e-14)
    with pytest.raises(ValueError, match=r"missing column\(s\) \['Tf'\]"):
        hb.simulate(m, p, df.drop(columns="Tf"))


def test_custom_network_two_rooms_from_dict():
    spec = {
        "name": "two_rooms",
        "domain": "thermal",
        "nodes": {"T1": "C1", "T2": "C2"},
        "links": [["T1", "Te", "G1"], ["T1", "T2", "G12"], ["T2", "Te", "G2"]],
        "inputs": ["Te", "I_S"],
        "outputs": ["T1", "T2"],
        "sources": [{"input": "I_S", "node": "T1", "gain": "fI_S"}],
    }
    m = RCModel(Network.from_dict(spec))
    assert m.parameter_names == ("C1", "C2", "G1", "G12", "G2", "fI_S")
    assert [i.unit for i in m.parameters] == ["J/K", "J/K", "W/K", "W/K", "W/K", "m²"]
    p = dict(C1=1e6, C2=2e6, G1=50.0, G12=30.0, G2=40.0, fI_S=2.0)
    U = np.column_stack([np.full(300, 10.0), np.r_[np.zeros(100), np.full(200, 200.0)]])
    y = hb.simulate(m, p, U)
    assert y.shape == (300, 2)
    assert y[-1, 0] > y[-1, 1] > 10.0  # the sunlit room is warmer
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['node'\]"):
        Network.from_dict({**spec, "node": {}})


def test_rejections_name_the_culprit():
    with pytest.raises(ValueError, match=r"\['T2'\] are not connected to any boundary"):
        Network(
            "bad",
            "thermal",
            (Node("T1", "C1"), Node("T2", "C2")),
            (Link("T1", "Te", "G1"),),
            ("Te",),
            ("T1",),
        )
    with pytest.raises(ValueError, match="unknown node 'Tx'"):
        Network("bad", "thermal", (Node("T1", "C1"),), (Link("Tx", "Te", "G1"),), ("Te",), ("T1",))
    with pytest.raises(ValueError, match=r"inputs \['Tg'\] are not connected"):
        Network(
            "bad", "thermal", (Node("T1", "C1"),), (Link("T1", "Te", "G1"),), ("Te", "Tg"), ("T1",)
        )
    with pytest.raises(ValueError, match="source input 'I' is not among"):
        Network(
            "bad",
            "thermal",
            (Node("T1", "C1"),),
            (Link("T1", "Te", "G1"),),
            ("Te",),
            ("T1",),
            sources=(Source("I", "T1", "g"),),
        )
    m = hb.model("thermal_4a")
    with pytest.raises(ValueError, match="capacity Ci must be > 0"):
        m.state_space({**P4A, "Ci": 0.0})
    with pytest.raises(ValueError, match="capacity Cw must be > 0"):
        hb.simulate(m, {**P4A, "Cw": -1.0}, np.zeros((5, 6)))
    with pytest.raises(ValueError, match="fraction fsol must be within"):
        hb.simulate(m, {**P4A, "fsol": 1.5}, np.zeros((5, 6)))
    with pytest.raises(ValueError, match=r"missing \['Gf'\]"):
        hb.simulate(m, {k: v for k, v in P4A.items() if k != "Gf"}, np.zeros((5, 6)))
    with pytest.raises(ValueError, match=r"unknown \['Gx'\]"):
        hb.simulate(m, {**P4A, "Gx": 1.0}, np.zeros((5, 6)))
    with pytest.raises(ValueError, match=r"expected an \(N, 6\) array .*got shape \(5, 5\)"):
        hb.simulate(m, P4A, np.zeros((5, 5)))
    U = np.zeros((5, 6))
    U[3, 2] = np.nan
    with pytest.raises(ValueError, match=r"column 'I_E' has a non-finite value .* row 3"):
        hb.simulate(m, P4A, U)
    for dt in (0.0, -3600.0, float("nan")):
        with pytest.raises(ValueError, match="dt must be a positive number"):
            hb.simulate(m, P4A, np.zeros((5, 6)), dt=dt)
    with pytest.raises(ValueError, match="unknown model 'thermal_9z'"):
        hb.model("thermal_9z")
    with pytest.raises(ValueError, match="facades: unknown key; did you mean 'surfaces'"):
        hb.model("thermal_4a", facades=("S",))
    with pytest.raises(ValueError, match="common length"):
        hb.simulate(m, {**P4A, "Ci": np.ones(3) * 1e6, "Cw": np.ones(4) * 1e8}, np.zeros((5, 6)))


def test_model_options_surfaces_heating_and_no_ground():
    m = hb.model("thermal_4a", surfaces=("S", "roof"), heating=True)
    assert m.input_names == ("Te", "I_S", "I_roof", "Tf", "Ph")
    assert "fI_roof" in m.parameter_names
    _, B, _, _ = m.state_space(
        {**{k: v for k, v in P4A.items() if not k.startswith("fI")}, "fI_S": 1.0, "fI_roof": 2.0}
    )
    assert B[1, 4] == pytest.approx(1 / P4A["Ci"])  # heating power with known gain 1
    m2 = hb.model("thermal_1c", ground=False)
    assert m2.input_names == ("Te", "I_N", "I_E", "I_S", "I_W")
    assert "Gf" not in m2.parameter_names


def test_invalid_parameter_sets_are_flagged_not_raised_in_modal_form():
    m = hb.model("thermal_4a")
    P = np.tile(m.param_array(P4A)[0], (3, 1))
    P[1, 1], P[2, 1] = -1.0, np.nan  # Ci
    mf = modal_form(m, P, 3600.0)
    np.testing.assert_array_equal(mf.valid, [True, False, False])
    assert np.all(np.isfinite(mf.ad))


def test_estimated_fixed_temperature_node():
    """ground="estimate": Tf is a constant parameter [°C] (thermal counterpart of Pf)."""
    m = hb.model("thermal_2c", surfaces=(), ground="estimate")
    assert m.input_names == ("Te",)
    assert m.parameter_names[-1] == "Tf" and m.parameters[-1].unit == "°C"
    p = dict(Cw=2e8, Ci=2e6, Gw=400.0, Gi=1600.0, Gfast=130.0, Gf=100.0, Tf=15.0)
    y = hb.simulate(m, p, np.full((10, 1), 3.0))
    A, B, _, _ = m.state_space(p)
    x_ss = np.linalg.solve(-A, B @ [3.0] + m.offset(p))
    np.testing.assert_allclose(y[:, 0], x_ss[1], rtol=1e-12)
    assert 3.0 < y[-1, 0] < 15.0
    with pytest.raises(ValueError, match="option ground must be"):
        hb.model("thermal_2c", ground="maybe")


# ------------------------------------------------ first-order hold (issue 31)
def _foh_expm(A, B, dt):
    """Triangle-hold equivalent from one matrix exponential (Franklin, Powell & Workman
    sec. 6.3.2): expm([[A dt, B dt, 0], [0, 0, I], [0, 0, 0]]) -> Phi, Gamma1, Gamma2."""
    n, m = B.shape
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n], M[:n, n : n + m] = A * dt, B * dt
    M[n : n + m, n + m :] = np.eye(m)
    E = expm(M)
    G1, G2 = E[:n, n : n + m], E[:n, n + m :]
    return E[:n, :n], G1 - G2, G2


@pytest.mark.parametrize("params", STIFF)
@pytest.mark.parametrize("dt", [60.0, 3600.0, 86400.0])
def test_first_order_hold_matches_expm(params, dt):
    m = hb.model("thermal_4a")
    A, B, _, _ = m.state_space(params)
    Ad, B0, B1, ed = hb.rc.discretize_foh(m, params, dt)
    Aref, B0ref, B1ref = _foh_expm(A, B, dt)
    assert np.abs(Ad - Aref).max() <= 1e-9 * np.abs(Aref).max()
    for got, ref in ((B0, B0ref), (B1, B1ref)):
        assert np.abs(got - ref).max() <= 1e-9 * np.abs(ref).max()
    # an input held constant: FOH and ZOH are the same step
    _, Bd, _, _, _ = hb.discretize(m, params, dt)
    np.testing.assert_allclose(B0 + B1, Bd, rtol=1e-9, atol=1e-12 * np.abs(Bd).max())
    np.testing.assert_array_equal(ed, 0.0)


def test_foh_weights_limits_and_series_branch():
    from heritage_bayes.rc import foh_weights

    dt = 3600.0
    # both dt/2 for a mode much slower than the step (the trapezoid rule)
    w0, w1 = foh_weights(np.array([0.0, 1e-15]), dt)
    np.testing.assert_allclose([w0, w1], dt / 2, rtol=1e-9)
    # the series (x < 1e-2) and the closed form agree where they meet, to rounding
    lam = np.array([0.99999e-2, 1.00001e-2]) / dt
    w0, w1 = foh_weights(lam, dt)
    np.testing.assert_allclose(w0[0], w0[1], rtol=1e-5)
    # a mode far faster than the step follows the input: all weight on u[k+1]
    w0, w1 = foh_weights(np.array([1.0]), dt)
    np.testing.assert_allclose([w0[0], w1[0]], [1.0 / 3600.0, 1.0 - 1.0 / 3600.0], rtol=1e-9)


def test_first_order_hold_is_exact_for_a_linear_input():
    """A 2-node room driven by inputs linear between hourly samples: FOH equals a
    2000-substep simulation of the ramp; ZOH of the interval mean (what the aligned frame
    holds) is off for the air node, by about the FOH slope term c = lambda dt²/12."""
    m = hb.model("thermal_2c", surfaces=("S",))
    p = dict(Cw=5e7, Ci=3e5, Gw=200.0, Gi=800.0, Gfast=150.0, Gf=20.0, fI_S=3.0)
    A, B, _, _ = m.state_space(p)
    rng = np.random.default_rng(0)
    N, sub, dt = 48, 2000, 3600.0
    samples = rng.normal(10.0, 4.0, (N + 1, m.n_inputs))
    Ad, B0, B1, _ = hb.rc.discretize_foh(m, p, dt)
    Af, Bf = _zoh_expm(A, B, dt / sub)
    x_foh = x_fine = np.linalg.solve(-A, B @ samples[0])
    x_zoh = x_foh.copy()
    _, Bd, _, _, _ = hb.discretize(m, p, dt)
    for k in range(N):
        x_foh = Ad @ x_foh + B0 @ samples[k] + B1 @ samples[k + 1]
        x_zoh = Ad @ x_zoh + Bd @ (0.5 * (samples[k] + samples[k + 1]))
        for j in range(sub):  # midpoint of each sub-step of the ramp
            u = samples[k] + (j + 0.5) / sub * (samples[k + 1] - samples[k])
            x_fine = Af @ x_fine + Bf @ u
    scale = np.abs(x_fine).max()
    # held midpoints of 2000 sub-steps approximate the ramp to O((dt/sub)²)
    assert np.abs(x_foh - x_fine).max() <= 1e-6 * scale
    assert np.abs(x_zoh - x_fine).max() > 100 * np.abs(x_foh - x_fine).max()
