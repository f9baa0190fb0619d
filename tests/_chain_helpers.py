"""Helpers shared by the sampler's tests: a ridge-shaped target and an interrupted,
then resumed chain."""

from __future__ import annotations

import numpy as np
import pytest

from heritage_bayes.inference.sampler import run_sampler


def sunny_room_inputs(m, N: int, rng: np.random.Generator) -> np.ndarray:
    """(N, m) hourly inputs of a room with one south surface: a daily outdoor cycle on a
    random walk [°C], the sun on the surface [W/m²] and a ground at 10 °C."""
    t = np.arange(N)
    cols = {
        "Te": 5 + 4 * np.sin(2 * np.pi * (t - 14) / 24) + np.cumsum(rng.normal(0, 0.3, N)),
        "I_S": np.clip(400 * np.sin(2 * np.pi * (t - 6) / 24), 0, None),
        "Tf": np.full(N, 10.0),
    }
    return np.column_stack([cols[c] for c in m.input_names])


class Ridge:
    """A 3-d Gaussian with correlations 0.99 (a ridge: τ of tens of steps), vectorised."""

    def __init__(self):
        self.cov = np.full((3, 3), 0.99) + 0.01 * np.eye(3)
        self.P = np.linalg.inv(self.cov)

    def __call__(self, X):
        X = np.atleast_2d(X)
        return -0.5 * np.einsum("ki,ij,kj->k", X, self.P, X)


def interrupt_at(f, path, step: int = 1650, max_steps: int = 2500, **kw) -> None:
    """Run ``f``'s chain (checkpoint ``path``) with a Ctrl-C at ``step``: emcee calls the
    log-posterior twice per step (once per half-ensemble) plus once at the start."""

    class Interrupting:
        def __init__(self, after):
            self.n, self.after = 0, after

        def __call__(self, X):
            self.n += 1
            if self.n == self.after:
                raise KeyboardInterrupt
            return f(X)

    with pytest.raises(KeyboardInterrupt):
        run_sampler(
            Interrupting(2 * step + 1), np.zeros(3), max_steps=max_steps, checkpoint=path, **kw
        )
