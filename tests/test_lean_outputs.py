"""Lean run outputs (issue 28): a bounded posterior predictive with exact bands, and a
compressed ``posterior.nc`` whose rounding stays below what any consumer resolves."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
import xarray as xr

from heritage_bayes._arviz import az
from heritage_bayes.inference.predictive import (
    BAND_LEVELS,
    PREDICTIVE_DRAWS,
    bounded_predictive,
    predictive_bands,
)
from heritage_bayes.inference.results import (
    PREDICTIVE_QUANTUM,
    _round_mantissa,
    as_stored,
    write_inference_data,
)
from heritage_bayes.report.rundata import predictive_quantiles


def _pp(rng, W=32, D=40, N=500):
    t = np.arange(N).astype("datetime64[h]").astype("datetime64[ns]")
    coords = {"chain": np.arange(W), "draw": np.arange(D), "time": t}
    base = 15 + 5 * np.sin(np.arange(N) / 24 * 2 * np.pi)
    Ti = base + rng.normal(0, 0.5, (W, D, N))
    Pi = 1200 + 100 * rng.standard_normal((W, D, N))
    return {
        "thermal.Ti": xr.DataArray(
            Ti.astype(np.float32), dims=tuple(coords), coords=coords, attrs={"unit": "°C"}
        ),
        "hygric.Pi": xr.DataArray(
            Pi.astype(np.float32), dims=tuple(coords), coords=coords, attrs={"unit": "Pa"}
        ),
    }


def test_bands_are_exact_over_all_draws_and_the_subset_is_bounded():
    pp = _pp(np.random.default_rng(1))
    bands = predictive_bands(pp)
    for k, da in pp.items():
        flat = da.values.reshape(-1, da.sizes["time"]).astype(float)
        np.testing.assert_allclose(
            bands[k].values, np.quantile(flat, BAND_LEVELS, axis=0), rtol=1e-6
        )
        assert bands[k].attrs["unit"] == da.attrs["unit"]
    sub = bounded_predictive(pp)
    n = sub["thermal.Ti"].sizes["chain"] * sub["thermal.Ti"].sizes["draw"]
    # the same draws of every chain, about PREDICTIVE_DRAWS in all, labels kept
    assert PREDICTIVE_DRAWS <= n < PREDICTIVE_DRAWS + 32
    np.testing.assert_array_equal(sub["thermal.Ti"]["draw"], sub["hygric.Pi"]["draw"])
    d = sub["thermal.Ti"]["draw"].values
    np.testing.assert_array_equal(sub["thermal.Ti"].values, pp["thermal.Ti"].values[:, d])


def test_round_mantissa_bounds_the_relative_error():
    x = np.random.default_rng(2).normal(-3, 2, 10_000).astype(np.float32)
    x[:3] = [np.nan, -np.inf, 0.0]
    r = _round_mantissa(x, 12)
    ok = np.isfinite(x)
    rel = np.abs(r[ok] - x[ok]) / np.maximum(np.abs(x[ok]), 1e-30)
    assert rel.max() <= 2.0**-13
    assert np.isnan(r[0]) and r[1] == -np.inf and r[2] == 0.0
    # the low 11 bits are zero: what makes the terms compress
    assert not np.any(r[ok].view(np.uint32) & np.uint32((1 << 11) - 1))


def test_written_file_is_compressed_packed_and_read_back_within_the_quantum(tmp_path):
    rng = np.random.default_rng(3)
    pp = _pp(rng)
    W, D = 32, 40
    ll = xr.DataArray(
        rng.normal(-1.5, 0.3, (W, D, 500)).astype(np.float32),
        dims=("chain", "draw", "time.thermal.Ti"),
    )
    post = xr.DataArray(rng.lognormal(10, 1, (W, D)), dims=("chain", "draw"))
    idata = az.InferenceData(
        posterior=xr.Dataset({"thermal.Ci": post}),
        log_likelihood=xr.Dataset({"thermal.Ti": ll}),
        posterior_predictive=xr.Dataset(bounded_predictive(pp)),
        predictive_bands=xr.Dataset(predictive_bands(pp)),
    )
    path = tmp_path / "posterior.nc"
    write_inference_data(idata, path)
    back = az.from_netcdf(str(path), engine="h5netcdf")
    # posterior draws keep full precision
    np.testing.assert_array_equal(back.posterior["thermal.Ci"].values, post.values)
    # predictive: within half a quantum of the unit
    for k in pp:
        q = PREDICTIVE_QUANTUM[pp[k].attrs["unit"]]
        got = back.posterior_predictive[k].values
        want = idata.posterior_predictive[k].values
        assert np.abs(got - want).max() <= q / 2 + 1e-6 * np.abs(want).max()
        bands = predictive_quantiles(back, k, [0.05, 0.5, 0.95])
        assert np.abs(bands - idata["predictive_bands"][k].values[[0, 2, 4]]).max() <= q
        # as_stored gives the values the file gives back, bit for bit (the summary's
        # band coverage is computed from them: a reader recomputes the same figure)
        np.testing.assert_array_equal(as_stored(want, pp[k].attrs["unit"]), got)
    # log-likelihood terms: relative error 2**-13
    d = np.abs(back.log_likelihood["thermal.Ti"].values - ll.values)
    assert np.all(d <= np.abs(ll.values) * 2.0**-13)
    with h5py.File(path) as f:
        ds = f["posterior_predictive/thermal.Ti"]
        assert ds.compression == "gzip" and ds.shuffle and ds.dtype == np.int32
        assert f["log_likelihood/thermal.Ti"].compression == "gzip"
        # every draw of up to 256 hours per chunk (the draws of one hour compress together)
        assert f["log_likelihood/thermal.Ti"].chunks == (W, D, 256)
        assert f["posterior_predictive/thermal.Ti"].chunks[2] == 256
        stored = sum(
            f[g][v].id.get_storage_size() for g in f for v in f[g] if hasattr(f[g][v], "id")
        )
    raw = sum(int(idata[g].nbytes) for g in idata.groups())
    assert stored < 0.6 * raw


def test_report_quantiles_fall_back_to_the_draws_of_old_runs():
    pp = _pp(np.random.default_rng(4))
    idata = az.InferenceData(posterior_predictive=xr.Dataset(pp))
    q = predictive_quantiles(idata, "hygric.Pi", [0.25, 0.75])
    flat = pp["hygric.Pi"].values.reshape(-1, 500).astype(float)
    np.testing.assert_allclose(q, np.quantile(flat, [0.25, 0.75], axis=0))
    with pytest.raises(KeyError):
        predictive_quantiles(idata, "thermal.Pi", [0.5])
