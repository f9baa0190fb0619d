"""Exact zero-order-hold discretization of RC networks, batched over parameter sets.

For an RC network :math:`A = -C^{-1}\\mathbf{G}` with :math:`C` diagonal positive and
:math:`\\mathbf{G}` symmetric positive definite (every node reaches a boundary), so
:math:`A` is similar to the symmetric matrix
:math:`-S = -C^{-1/2}\\mathbf{G}C^{-1/2} = -V\\Lambda V^T`: its eigenvalues
:math:`-\\lambda_j` are real and negative. With :math:`x = Tz`,
:math:`T = C^{-1/2}V`, :math:`T^{-1} = V^T C^{1/2}`, the modes decouple:

.. math::

    z_j[k+1] = e^{-\\lambda_j \\Delta t} z_j[k]
               + \\frac{1 - e^{-\\lambda_j\\Delta t}}{\\lambda_j}
                 \\left(\\tilde B u[k] + \\tilde e\\right)_j,
    \\qquad \\tilde B = V^T C^{-1/2} G_u,

which is the exact zero-order-hold solution (``u[k]`` held over
:math:`[t_k, t_{k+1})`). ``-expm1`` keeps the gain accurate for slow modes (time constants
of years) and the decay exact for fast ones (minutes).

Inputs sampled at instants (outdoor temperature read at the hour) are better described
as linear between the samples: the **first-order hold** (triangle hold) is exact for
them and just as closed-form per mode (:func:`foh_weights`, :func:`discretize_foh`):

.. math::

    z_j[k+1] = a_j z_j[k] + w^-_j (\tilde B u[k])_j + w^+_j (\tilde B u[k+1])_j
               + \\phi_j \tilde e_j,\\qquad
    w^-_j = \frac{1 - a_j(1 + \\lambda_j\\Delta t)}{\\lambda_j^2\\Delta t},\\quad
    w^+_j = \\phi_j - w^-_j,

with :math:`a_j = e^{-\\lambda_j\\Delta t}` and :math:`\\phi_j = (1 - a_j)/\\lambda_j`.
Written with the interval mean :math:`\bar u_k = (u[k] + u[k+1])/2` that
:func:`heritage_bayes.io.align` puts on row ``k`` for an instantaneous column, the
forcing is :math:`\\phi_j \tilde B \bar u_k + c_j \tilde B (u[k+1] - u[k])` with the
slope gain :math:`c_j = (w^+_j - w^-_j)/2 \approx \\lambda_j\\Delta t^2/12` for slow
modes: the zero-order hold of the interval mean is exact for modes much slower than
the step, and the slope term corrects the fast (air) modes.

References
----------
.. [1] G.F. Franklin, J.D. Powell, M.L. Workman, *Digital Control of Dynamic Systems*,
   3rd ed., Addison-Wesley, 1998, ch. 4 (zero-order-hold equivalent) and sec. 6.3.2
   (triangle-hold equivalent).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ModalForm", "discretize", "discretize_foh", "foh_weights", "modal_form"]


@dataclass
class ModalForm:
    """Decoupled (modal) discrete-time form of a batch of RC networks.

    Attributes
    ----------
    lam : (K, n) array
        Decay rates :math:`\\lambda_j` [1/s] (time constants :math:`1/\\lambda_j`).
    ad : (K, n) array
        Discrete modal poles :math:`e^{-\\lambda_j\\Delta t}`.
    Bz : (K, n, m) array
        Continuous modal input matrix :math:`V^T C^{-1/2} G_u`.
    ez : (K, n) array
        Continuous modal constant forcing.
    phi : (K, n) array
        ZOH gain factor :math:`(1-e^{-\\lambda\\Delta t})/\\lambda` [s].
    Cz : (K, n_out, n) array
        Output matrix in modal coordinates :math:`C\\,C_{cap}^{-1/2}V`.
    s, V : (K, n), (K, n, n) arrays
        :math:`C_{cap}^{-1/2}` and the eigenvectors: the state transformation
        :attr:`T` (:math:`x = Tz`) and :attr:`Tinv` are built from them on demand.
    valid : (K,) bool
        Parameter sets that are admissible and gave finite, positive decay rates.
    dt : float
        Time step [s].
    slope : (m,) bool array or None
        Input columns that are an input's change over the step,
        :math:`u(t_{k+1}) - u(t_k)` (first-order hold, :meth:`RCModel.with_slopes`);
        their discrete weight is :attr:`cs` instead of :attr:`phi`. None: no such column
        (every input held over the step).
    cs : (K, n) array or None
        FOH slope gain :math:`c_j = (w^+_j - w^-_j)/2` [s] of :func:`foh_weights`.
    """

    lam: np.ndarray
    ad: np.ndarray
    Bz: np.ndarray
    ez: np.ndarray
    phi: np.ndarray
    Cz: np.ndarray
    s: np.ndarray
    V: np.ndarray
    valid: np.ndarray
    dt: float
    slope: np.ndarray | None = None
    cs: np.ndarray | None = None

    @property
    def T(self) -> np.ndarray:
        """(K, n, n) state transformation :math:`x = Tz`, :math:`T = C^{-1/2}V`."""
        return self.s[:, :, None] * self.V

    @property
    def Tinv(self) -> np.ndarray:
        """(K, n, n) inverse transformation :math:`T^{-1} = V^T C^{1/2}`."""
        return np.swapaxes(self.V, 1, 2) / self.s[:, None, :]

    @property
    def Bdz(self) -> np.ndarray:
        r"""Discrete modal input matrix (K, n, m): :math:`\phi_j` times the columns of
        the inputs' interval means, :math:`c_j` times their slope columns (FOH)."""
        if self.slope is None:
            return self.phi[:, :, None] * self.Bz
        w = np.where(self.slope[None, None, :], self.cs[:, :, None], self.phi[:, :, None])
        return w * self.Bz

    def _steady_Bz(self, width: int) -> np.ndarray:
        """Bz for a steady state: slope columns are zero in steady state; ``width``
        may also be that of the network's inputs without their slope columns."""
        if self.slope is None:
            return self.Bz
        if width == self.slope.size:
            return np.where(self.slope[None, None, :], 0.0, self.Bz)
        return self.Bz[:, :, : int((~self.slope).sum())]

    @property
    def edz(self) -> np.ndarray:
        """Discrete modal constant forcing (K, n)."""
        return self.phi * self.ez

    def steady_state_modal(self, u0: np.ndarray) -> np.ndarray:
        """Modal steady state for constant inputs ``u0`` ((m,) or (K, m)): (K, n)."""
        u0 = np.asarray(u0, dtype=float)
        forcing = np.einsum("knm,...m->kn", self._steady_Bz(u0.shape[-1]), u0) + self.ez
        with np.errstate(divide="ignore", invalid="ignore"):
            return forcing / self.lam

    def to_modal(self, x0: np.ndarray) -> np.ndarray:
        """Physical state(s) ``x0`` ((n,) or (K, n)) -> modal (K, n)."""
        x0 = np.asarray(x0, dtype=float)
        if x0.ndim == 1:
            return np.einsum("kij,j->ki", self.Tinv, x0)
        return np.einsum("kij,kj->ki", self.Tinv, x0)


def modal_form(model, P: np.ndarray, dt: float) -> ModalForm:
    """Modal decomposition and exact ZOH discretization of a batch of parameter sets.

    Parameters
    ----------
    model : RCModel
    P : (K, n_params) array
        Parameter sets in ``model.parameter_names`` order, SI units.
    dt : float
        Time step [s].

    Returns
    -------
    ModalForm
        Invalid parameter sets (non-physical values, non-finite results) are marked in
        ``valid`` and replaced by a harmless stable placeholder, never raised: the
        log-posterior turns them into ``-inf``.
    """
    P = np.atleast_2d(np.asarray(P, dtype=float))
    valid = model.valid_mask(P)
    if not valid.all():
        # a stable placeholder (unit capacities and conductances) for invalid rows
        P = P.copy()
        P[~valid] = 1.0
        frac = [j for j, i in enumerate(model.parameters) if i.kind == "fraction"]
        P[np.ix_(~valid, frac)] = 0.5
    cap, G, Gu, q = model.network_matrices(P)
    s = 1.0 / np.sqrt(cap)  # C^-1/2
    S = s[:, :, None] * G * s[:, None, :]
    lam, V = np.linalg.eigh(S)
    Vt = np.swapaxes(V, 1, 2)
    Bz = Vt @ (s[:, :, None] * Gu)
    slope = getattr(model, "slope_mask", None)
    if slope is not None:  # FOH: each slope column couples like its input
        Bz = np.concatenate([Bz, Bz[:, :, list(model.slope_sources)]], axis=2)
    ez = np.einsum("kij,kj->ki", Vt, s * q) if q.any() else np.zeros_like(lam)
    # outputs are node potentials: rows of T = C^-1/2 V for the observed nodes
    out = model._ix["out"]
    Cz = s[:, out, None] * V[:, out, :]
    x = lam * dt
    # poles below 1e-200 (modes faster than dt/460) are flushed to exactly zero: the
    # same result to machine precision, without subnormal arithmetic in the recursion
    ad = np.exp(-x)
    ad[ad < 1e-200] = 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(x > 1e-300, -np.expm1(-x) / np.where(lam > 0, lam, 1.0), dt)
    ok = valid & np.all(np.isfinite(lam), axis=1) & np.all(lam > 0, axis=1)
    ok &= np.all(np.isfinite(Bz), axis=(1, 2))
    cs = None
    if slope is not None:
        w0, w1 = foh_weights(np.where(lam > 0, lam, 0.0), dt)
        cs = 0.5 * (w1 - w0)
    # positional, in the field order: lam, ad, Bz, ez, phi, Cz, s, V, valid, dt, slope, cs
    return ModalForm(lam, ad, Bz, ez, phi, Cz, s, V, ok, float(dt), slope, cs)


def discretize(model, params, dt: float = 3600.0):
    """Exact ZOH discretization: ``x[k+1] = Ad x[k] + Bd u[k] (+ ed)``, ``y = C x + D u``.

    Parameters
    ----------
    model : RCModel
    params : mapping name -> float, or name -> (K,) arrays for a batch [SI units]
    dt : float
        Time step [s].

    Returns
    -------
    Ad : (n, n) or (K, n, n)
    Bd : (n, m) or (K, n, m)
    C : (n_out, n)
    D : (n_out, m)
    ed : (n,) or (K, n)
        Discrete constant forcing (zero unless the network has constant boundaries).
    """
    mf, batch, Ad, ed = _physical(model, params, dt)
    Bd = mf.T @ mf.Bdz
    Cm = model.output_matrix()
    D = np.zeros((model.n_outputs, model.n_inputs))
    if not batch:
        Ad, Bd, ed = Ad[0], Bd[0], ed[0]
    return Ad, Bd, Cm, D, ed


def _physical(model, params, dt):
    """(modal form, batch?, Ad, ed) in physical coordinates for :func:`discretize` and
    :func:`discretize_foh`."""
    dt = _check_dt(dt)
    P, batch = model.param_array(params)
    model.check_values(P)
    mf = modal_form(model, P, dt)
    Ad = (mf.T * mf.ad[:, None, :]) @ mf.Tinv
    ed = np.einsum("kij,kj->ki", mf.T, mf.edz)
    return mf, batch, Ad, ed


def _check_dt(dt) -> float:
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be a positive number of seconds (got {dt!r})") from None
    if not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive number of seconds (got {dt!r})")
    return dt


def foh_weights(lam, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact first-order-hold weights of a mode with decay rate ``lam`` [1/s].

    For an input linear between the samples ``u[k]`` and ``u[k+1]`` over a step ``dt``
    [s], the mode :math:`\\dot z = -\\lambda z + b\\,u(t)` gives
    :math:`z[k+1] = e^{-\\lambda\\Delta t} z[k] + b\\,(w^- u[k] + w^+ u[k+1])`.

    Parameters
    ----------
    lam : array_like
        Decay rates :math:`\\lambda \\ge 0` [1/s].
    dt : float
        Time step [s].

    Returns
    -------
    w_prev, w_next : arrays like ``lam`` [s]
        :math:`w^- = (1 - e^{-x}(1 + x)) / (\\lambda x)` and
        :math:`w^+ = (1 - e^{-x})/\\lambda - w^-` with :math:`x = \\lambda\\Delta t`;
        both :math:`\\Delta t/2` for :math:`\\lambda \to 0` (the trapezoid), and
        :math:`w^- \to 0`, :math:`w^+ \to 1/\\lambda` for very fast modes (the mode
        follows the input). A series is used for :math:`x < 10^{-2}` (no cancellation).

    Notes
    -----
    :math:`w^- = \\int_0^{\\Delta t} e^{-\\lambda s}\\,s/\\Delta t\\,ds` weights the sample at
    the start of the step, :math:`w^+` the one at its end [1]_.
    """
    dt = _check_dt(dt)
    lam = np.asarray(lam, dtype=float)
    x = lam * dt
    small = x < 1e-2
    xs = np.where(small, x, 0.0)
    # (1 - e^-x (1 + x)) / x^2 = 1/2 - x/3 + x^2/8 - x^3/30 + x^4/144 - x^5/840
    series = 0.5 + xs * (-1 / 3 + xs * (1 / 8 + xs * (-1 / 30 + xs * (1 / 144 - xs / 840))))
    xl = np.where(small, 1.0, x)
    big = (-np.expm1(-xl) - xl * np.exp(-xl)) / (xl * xl)
    w_prev = dt * np.where(small, series, big)
    with np.errstate(divide="ignore", invalid="ignore"):
        total = np.where(x > 1e-300, -np.expm1(-x) / np.where(lam > 0, lam, 1.0), dt)
    return w_prev, total - w_prev


def discretize_foh(model, params, dt: float = 3600.0):
    """Exact first-order-hold discretization of inputs linear between samples.

    ``x[k+1] = Ad x[k] + B0 u[k] + B1 u[k+1] (+ ed)``, ``y = C x``: exact when every
    input is linear between its samples at ``t_k`` and ``t_{k+1}`` (instantaneous
    readings, e.g. outdoor temperature at the hour), as :func:`discretize` is for
    inputs held over each step (interval means). Use one or the other per input
    column: an interval mean's column of ``B0 + B1`` is the ZOH column ``Bd``.
    Parameters as :func:`discretize` (``dt`` [s]).

    Returns
    -------
    Ad : (n, n) or (K, n, n)
    B0, B1 : (n, m) or (K, n, m)
        Weights of the samples at the start and at the end of the step.
    ed : (n,) or (K, n)
        Discrete constant forcing (as :func:`discretize`).
    """
    mf, batch, Ad, ed = _physical(model, params, dt)
    w0, w1 = foh_weights(mf.lam, mf.dt)
    B0 = mf.T @ (w0[:, :, None] * mf.Bz)
    B1 = mf.T @ (w1[:, :, None] * mf.Bz)
    if not batch:
        Ad, B0, B1, ed = Ad[0], B0[0], B1[0], ed[0]
    return Ad, B0, B1, ed
