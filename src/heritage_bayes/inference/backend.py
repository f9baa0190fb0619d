"""The HDF5 checkpoint of a chain: crash-consistent appends, resume, damage detection.

Like emcee's backends, a small object with one job: :class:`_Checkpoint` appends the
steps of a chain chunk by chunk (rows first, then one ``commit`` attribute that says
how many rows are valid, with SIGINT/SIGTERM deferred around it), loads the committed
prefix with the random-number state for ``--resume``, and explains a damaged file while
keeping its valid steps. Used by :mod:`heritage_bayes.inference.sampler`.
"""

from __future__ import annotations

import json
import signal
import threading
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from heritage_bayes.errors import InputError


def _open_for_append(path, tries: int = 60, wait: float = 0.5):
    """The chain file opened for appending. HDF5 locks the file: while another process
    reads it (a user looking at the running chain with h5py), opening it for writing
    fails with ``BlockingIOError``; wait for the reader (up to ``tries`` × ``wait`` s)
    rather than end a run of many minutes for it."""
    import time

    for _ in range(tries - 1):
        try:
            return h5py.File(path, "a")
        except BlockingIOError:
            time.sleep(wait)
    return h5py.File(path, "a")


class _DeferSignals:
    """Record SIGINT and SIGTERM instead of acting on them, for a critical section.

    ``received`` is the first signal number seen (or None). On exit the previous handlers
    come back and, with ``redeliver=True``, a recorded signal is raised again, so an
    interrupt during a checkpoint commit takes effect right after it. Only the main
    thread receives signals in Python; elsewhere this does nothing.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, redeliver: bool = True):
        self.redeliver = redeliver
        self.received: int | None = None
        self._old: dict = {}

    def __enter__(self):
        self.received = None
        if threading.current_thread() is threading.main_thread():
            for s in self.SIGNALS:
                if signal.getsignal(s) is signal.SIG_IGN:
                    continue  # ignored on purpose (nohup, a background job): keep it so
                old = signal.signal(s, self._record)
                self._old[s] = signal.SIG_DFL if old is None else old
        return self

    def _record(self, signum, frame):
        if self.received is None:
            self.received = signum

    def __exit__(self, *exc):
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old = {}
        if self.redeliver and self.received is not None and exc[0] is None:
            signal.raise_signal(self.received)
        return False


@dataclass
class _Saved:
    """What a checkpoint holds up to its last commit (see :meth:`_Checkpoint.load`)."""

    chain: np.ndarray
    log_prob: np.ndarray
    accepted: np.ndarray
    random_state: tuple | None
    tau_history: list
    problem: str | None = None  # what was wrong with the file, if anything


class _Checkpoint:
    """Appends chain chunks and the RNG state to an HDF5 file, crash-consistently.

    Every append writes the new rows first and then commits them with a single
    attribute, ``commit`` (JSON: iteration, acceptance counts, random state, τ
    history); rows beyond the committed ``iteration`` are ignored on load and
    overwritten by the next append, so an interrupt at any instant leaves the last
    commit intact. SIGINT/SIGTERM are deferred until the commit is done. The datasets
    carry Fletcher-32 checksums, so damaged chunks are detected on load and the valid
    prefix is kept. The file is created under a unique temporary name (never through
    a symlink) and renamed into place.
    """

    FORMAT = 2

    def __init__(self, path: Path, tag: str):
        self.path = Path(path)
        self.tag = tag

    def create(self, nwalkers: int, ndim: int) -> None:
        from heritage_bayes.inference.results import atomic_write, ensure_free_space

        ensure_free_space(self.path, 2 * 64 * nwalkers * (ndim + 1) * 8)

        def write(tmp: Path) -> None:
            with h5py.File(tmp, "w") as f:
                f.attrs["tag"] = self.tag
                f.attrs["format"] = self.FORMAT
                f.attrs["iteration"] = 0
                for name, shape in (("chain", (nwalkers, ndim)), ("log_prob", (nwalkers,))):
                    f.create_dataset(
                        name,
                        (0, *shape),
                        maxshape=(None, *shape),
                        dtype="f8",
                        chunks=(64, *shape),
                        fletcher32=True,
                    )

        atomic_write(self.path, write)

    def append(self, chain, log_prob, accepted, random_state, tau_history) -> None:
        """Write ``chain``/``log_prob`` rows after the last commit, then commit them."""
        from heritage_bayes.inference.results import ensure_free_space

        chunk = 64 * int(np.prod(chain.shape[1:])) * 8  # one HDF5 chunk [bytes]
        ensure_free_space(self.path, chain.nbytes + log_prob.nbytes + 2 * chunk)
        with _DeferSignals(), _open_for_append(self.path) as f:
            n0 = int(json.loads(f.attrs["commit"])["iteration"]) if "commit" in f.attrs else 0
            n = chain.shape[0]
            for name, rows in (("chain", chain), ("log_prob", log_prob)):
                f[name].resize(n0 + n, axis=0)
                f[name][n0:] = rows
            f.flush()
            name, keys, pos, has_gauss, cached = random_state
            commit = {
                "iteration": n0 + n,
                "accepted": np.asarray(accepted, dtype=float).tolist(),
                "rng": [
                    str(name),
                    np.asarray(keys).tolist(),
                    int(pos),
                    int(has_gauss),
                    float(cached),
                ],
                "tau_history": np.asarray(tau_history, dtype=float).reshape(-1, 2).tolist(),
            }
            f.attrs["commit"] = json.dumps(commit)  # the commit point
            f.attrs["iteration"] = n0 + n  # informative
            f.flush()

    def _damaged(self, why: str) -> InputError:
        return InputError(
            f"{self.path}: the chain checkpoint is damaged ({why}); it was left as it is. "
            "Run without --resume to start the chain afresh (the file is then replaced), "
            "or restore a good copy"
        )

    def load(self) -> _Saved:
        """The committed chain; damaged rows cut off (``problem`` says what and where).

        Raises
        ------
        InputError
            Not a readable checkpoint, or one made for another configuration.
        """
        try:
            f = h5py.File(self.path, "r")
        except OSError as exc:
            raise self._damaged(f"not a readable HDF5 file: {_first_line(exc)}") from None
        with f:
            tag = f.attrs.get("tag")
            if tag is None or "chain" not in f or "log_prob" not in f:
                raise self._damaged("no tag or chain datasets: not a checkpoint of hbayes")
            if tag != self.tag:
                raise InputError(
                    f"{self.path}: this checkpoint belongs to a different configuration, "
                    "model or data; run without --resume (it will be replaced) or restore "
                    "the config and data it was made with"
                )
            problem = None
            rs = None
            try:
                if "commit" in f.attrs:
                    c = json.loads(f.attrs["commit"])
                    n = int(c["iteration"])
                    accepted = np.asarray(c["accepted"], dtype=float)
                    name, keys, pos, has_gauss, cached = c["rng"]
                    rs = (
                        str(name),
                        np.asarray(keys, dtype=np.uint32),
                        int(pos),
                        int(has_gauss),
                        float(cached),
                    )
                    hist = [tuple(r) for r in c["tau_history"]]
                else:  # format 1 (before the commit attribute)
                    n = int(f.attrs.get("iteration", 0))
                    accepted = (
                        f["accepted"][...] if "accepted" in f else np.zeros(f["chain"].shape[1])
                    )
                    if "rng_name" in f.attrs:
                        rs = (
                            str(f.attrs["rng_name"]),
                            np.asarray(f.attrs["rng_keys"]),
                            int(f.attrs["rng_pos"]),
                            int(f.attrs["rng_has_gauss"]),
                            float(f.attrs["rng_cached"]),
                        )
                    elif n > 0:
                        problem = "it holds no random-number state"
                    hist = [tuple(r) for r in np.asarray(f.attrs.get("tau_history", []))]
            except (KeyError, ValueError, TypeError, OSError) as exc:
                raise self._damaged(f"unreadable commit record: {_first_line(exc)}") from None
            n = min(n, f["chain"].shape[0], f["log_prob"].shape[0])
            chain, lp, bad = _read_prefix(f["chain"], f["log_prob"], n)
        if bad is not None:
            problem = (
                f"steps {bad} to {n} are damaged; kept the {chain.shape[0]} valid steps before them"
            )
            rs = None  # the saved random state belongs to the end of the damaged part
        return _Saved(chain, lp, accepted, rs, hist[: max(0, len(hist))], problem)


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0][:200]


def _read_prefix(chain_ds, lp_ds, n: int, block: int = 64):
    """Rows ``[:n]`` of both datasets, block by block, up to the first damaged block
    (checksum error, or non-finite coordinates); returns ``(chain, log_prob, bad)``,
    ``bad`` the first damaged row or None."""
    xs, lps = [], []
    for i in range(0, n, block):
        j = min(n, i + block)
        try:
            x, lp = chain_ds[i:j], lp_ds[i:j]
        except (OSError, RuntimeError, ValueError):
            return _cat(xs, chain_ds), _cat(lps, lp_ds), i
        ok = np.isfinite(x).all(axis=(1, 2)) & ~np.isnan(lp).any(axis=1)
        if not ok.all():
            k = int(np.argmin(ok))
            xs.append(x[:k])
            lps.append(lp[:k])
            return _cat(xs, chain_ds), _cat(lps, lp_ds), i + k
        xs.append(x)
        lps.append(lp)
    return _cat(xs, chain_ds), _cat(lps, lp_ds), None


def _cat(parts, ds):
    return np.concatenate(parts) if parts else np.zeros((0, *ds.shape[1:]))


#: ``format`` attribute of a compacted checkpoint (see :func:`write_compact`).
COMPACT_FORMAT = "compact-1"
#: Steps per walker of the trace a compacted checkpoint keeps (the report's plots).
TRACE_STEPS = 400


def write_compact(path: Path, tag: str, draws, log_prob, info: dict, chain, chain_lp) -> None:
    """Replace a converged chain's checkpoint by the draws its outputs use.

    ``draws`` (kept steps, walkers, d) and ``log_prob`` (kept steps, walkers) are the
    post-burn-in, thinned steps (float64: at most ``sampler.max_draws`` × d values, a
    few hundred kB); ``info`` (JSON) records the chain they came from (steps, burn,
    thin, τ, τ history, acceptance counts). ``chain``/``log_prob`` hold a trace of
    the whole chain for plots, burn-in included: every ``trace_stride``-th step
    (attribute), at most :data:`TRACE_STEPS` per walker, float32. The full chain is
    what ``--resume`` needs while a chain is unconverged; once converged, these draws
    are all a resumed run needs to rebuild its outputs. Datasets gzip-compressed with
    Fletcher-32 checksums; written atomically.
    """
    stride = max(1, -(-int(chain.shape[0]) // TRACE_STEPS))
    from heritage_bayes.inference.results import atomic_write

    def write(tmp: Path) -> None:
        with h5py.File(tmp, "w") as f:
            f.attrs["tag"] = tag
            f.attrs["format"] = COMPACT_FORMAT
            f.attrs["compact"] = json.dumps(info)
            f.attrs["trace_stride"] = stride
            for name, a, dtype in (
                ("draws", draws, "f8"),
                ("draws_log_prob", log_prob, "f8"),
                ("chain", chain[::stride], "f4"),
                ("log_prob", chain_lp[::stride], "f4"),
            ):
                f.create_dataset(
                    name,
                    data=np.asarray(a, dtype=dtype),
                    compression="gzip",
                    shuffle=True,
                    fletcher32=True,
                )

    atomic_write(Path(path), write)


def read_compact(path: Path, tag: str) -> tuple[np.ndarray, np.ndarray, dict] | None:
    """(draws, log_prob, info) of a compacted checkpoint (:func:`write_compact`), or
    None for a full one (or none at all).

    Raises
    ------
    InputError
        A compacted checkpoint of another configuration, or an unreadable one.
    """
    path = Path(path)
    if not path.is_file():
        return None
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != COMPACT_FORMAT:
                return None
            if f.attrs.get("tag") != tag:
                raise InputError(
                    f"{path}: this checkpoint belongs to a different configuration, "
                    "model or data; run without --resume (it will be replaced) or restore "
                    "the config and data it was made with"
                )
            return f["draws"][...], f["draws_log_prob"][...], json.loads(f.attrs["compact"])
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(
            f"{path}: the compacted chain checkpoint is damaged ({_first_line(exc)}); run "
            "without --resume to sample afresh (the file is then replaced)"
        ) from None
