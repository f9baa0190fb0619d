"""The HDF5 checkpoint of a chain: crash-consistent appends, resume, damage detection.

Like emcee's backends, a small object with one job: :class:`_Checkpoint` appends the
steps of a chain chunk by chunk (rows first, then one ``commit`` attribute that says
how many rows are valid, with SIGINT/SIGTERM deferred around it), loads the committed
prefix with the random-number state for ``--resume``, and explains a damaged file while
keeping its valid steps. Used by :mod:`heritage_bayes.inference.sampler`.

Tamper evidence (format 3): every append is a *block* of rows whose SHA-256 is chained
to the previous block's (``h_k = sha256(h_{k-1} || chain rows || log_prob rows)``, as
stored), and the commit record's state (acceptance counts, random state, τ history) is
hashed onto the last block. ``--resume`` recomputes the chain and refuses a checkpoint
whose rows or state were edited, naming the first block that differs. (HDF5's
Fletcher-32 catches storage damage, not an edit: h5py recomputes it on write.)
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from heritage_bayes.errors import InputError
from heritage_bayes.rundir.signals import DeferSignals


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


@dataclass
class _Saved:
    """What a checkpoint holds up to its last commit (see :meth:`_Checkpoint.load`)."""

    chain: np.ndarray
    log_prob: np.ndarray
    accepted: np.ndarray
    random_state: tuple | None
    tau_history: list
    problem: str | None = None  # what was wrong with the file, if anything
    stride: int = 1  # steps per stored row (a thinned chain)
    steps: int | None = None  # steps of the chain (None: one per row)
    last: tuple | None = None  # (positions, log-probabilities) of its last step
    internal: np.ndarray | None = None  # the last step in the sampler's own coordinates


class _Checkpoint:
    """Appends chain chunks and the RNG state to an HDF5 file, crash-consistently.

    Every append writes the new rows first and then commits them with a single
    attribute, ``commit`` (JSON: iteration, acceptance counts, random state, τ
    history); rows beyond the committed ``iteration`` are ignored on load and
    overwritten by the next append, so an interrupt at any instant leaves the last
    commit intact. SIGINT/SIGTERM are deferred until the commit is done. The datasets
    carry Fletcher-32 checksums, so damaged chunks are detected on load and the valid
    prefix is kept. The file is created under a unique temporary name (never through
    a symlink) and renamed into place. The rows are gzip-compressed (lossless; rejected
    proposals repeat rows; sizes and CPU: docs/science/benchmarks.md, "Bounded chains").
    """

    FORMAT = 3

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
                        # lossless: rejected proposals repeat a walker's row, which
                        # compresses well at a low acceptance (figure: docs/science/
                        # benchmarks.md, "Figures behind the code's choices")
                        compression="gzip",
                        compression_opts=4,
                    )

        atomic_write(self.path, write)

    def append(self, chain, log_prob, accepted, random_state, tau_history, **thinned) -> None:
        """Write ``chain``/``log_prob`` rows after the last commit, then commit them.

        A thinned chain (keyword ``stride`` > 1 steps per row, see
        :class:`heritage_bayes.inference.monitor.ChainBuffer`) also commits its length
        ``steps`` and ``last`` = (positions (walkers, d), log-probabilities (walkers,))
        of its last step, where ``--resume`` continues (the last step is not always a
        stored row); at stride 1 the commit record is as before. ``internal``
        (walkers, d): the last step's positions in the sampler's own coordinates when
        they are not the stored ones (a transform whose round trip is exact only to
        rounding), so that a resumed chain continues bit for bit."""
        from heritage_bayes.inference.results import ensure_free_space

        chunk = 64 * int(np.prod(chain.shape[1:])) * 8  # one HDF5 chunk [bytes]
        ensure_free_space(self.path, chain.nbytes + log_prob.nbytes + 2 * chunk)
        with DeferSignals(), _open_for_append(self.path) as f:
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
            if thinned.get("internal") is not None:
                commit["internal"] = np.asarray(thinned["internal"], dtype=float).tolist()
            if thinned.get("stride", 1) > 1:
                commit["stride"] = int(thinned["stride"])
                commit["steps"] = int(thinned["steps"])
                commit["last"] = [np.asarray(a, dtype=float).tolist() for a in thinned["last"]]
            rows = [
                np.asarray(r, dtype=f[k].dtype)
                for k, r in (("chain", chain), ("log_prob", log_prob))
            ]
            commit["n_blocks"], last = _append_block(f, n0, n0 + n, rows)
            commit["state_sha256"] = _state_sha(last, commit)
            f.attrs["commit"] = json.dumps(commit)  # the commit point
            f.attrs["iteration"] = n0 + n  # informative
            f.flush()

    def rewrite(self, chain, log_prob, accepted, random_state, tau_history, **thinned) -> None:
        """Replace the file by one holding these rows and this commit (a thinned chain
        whose stride doubled: :meth:`append`'s keywords), atomically: written under
        another name, then renamed over the checkpoint, so an interrupt leaves either
        the old or the new file whole."""
        tmp = _Checkpoint(self.path.with_name(self.path.name + ".thinning"), self.tag)
        tmp.create(chain.shape[1], chain.shape[2])
        tmp.append(chain, log_prob, accepted, random_state, tau_history, **thinned)
        with DeferSignals():
            os.replace(tmp.path, self.path)

    def _damaged(self, why: str) -> InputError:
        return InputError(
            f"{self.path}: the chain checkpoint is damaged ({why}); it was left as it is. "
            "Run without --resume to start the chain afresh (the file is then replaced), "
            "or restore a good copy"
        )

    def _verify(self, f, commit: dict, chain, lp, n: int) -> None:
        """Recompute the block checksums of the rows read (blocks cut short by storage
        damage are left to the damage report) and of the commit state."""
        nb = commit.get("n_blocks")
        if not isinstance(nb, int) or "state_sha256" not in commit or "block_sha" not in f:
            raise self._damaged("format 3 without its block checksums")
        try:
            ends = f["block_end"][:nb].astype(int)
            shas = [b.decode("ascii") for b in f["block_sha"][:nb]]
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            raise self._damaged(f"unreadable block checksums: {_first_line(exc)}") from None
        if len(shas) != nb:
            raise self._damaged(f"{len(shas)} block checksums, the commit says {nb}")
        prev, a = _GENESIS, 0
        for k, (b, sha) in enumerate(zip(ends, shas, strict=True), start=1):
            if b > n:
                raise self._edited(f"the commit record (it says {n} steps, block {k} ends at {b})")
            if b > chain.shape[0]:  # beyond the readable prefix (damage reported)
                return
            if _block_sha(prev, chain[a:b], lp[a:b]) != sha:
                raise self._edited(f"block {k} (steps {a + 1} to {b})")
            prev, a = sha, b
        if a != n:
            raise self._edited(f"the commit record (it says {n} steps, the blocks {a})")
        if _state_sha(prev, commit) != commit["state_sha256"]:
            raise self._edited("the commit record (acceptance counts, random state, τ history)")

    def _edited(self, what: str) -> InputError:
        return InputError(
            f"{self.path}: {what} does not match its checksum: the checkpoint was changed "
            "after hbayes wrote it, so --resume would continue a chain that was not "
            "sampled. Run without --resume to start the chain afresh (the file is then "
            "replaced), or restore the original file"
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
            stride, steps, last, internal = 1, None, None, None
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
                    stride, steps = int(c.get("stride", 1)), c.get("steps")
                    last = c.get("last")
                    if c.get("internal") is not None:
                        internal = np.asarray(c["internal"], dtype=float)
                    if last is not None:
                        last = (np.asarray(last[0], dtype=float), np.asarray(last[1], dtype=float))
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
            if "commit" in f.attrs and int(f.attrs.get("format", 2)) >= 3:
                self._verify(f, json.loads(f.attrs["commit"]), chain, lp, n)
        if bad is not None:
            problem = (
                f"steps {bad} to {n} are damaged; kept the {chain.shape[0]} valid steps before them"
            )
            rs = internal = None  # the saved state belongs to the end of the damaged part
            # a thinned chain continues from its last valid row
            steps = chain.shape[0] * stride
            last = (chain[-1], lp[-1]) if chain.shape[0] else None
        return _Saved(
            chain,
            lp,
            accepted,
            rs,
            hist[: max(0, len(hist))],
            problem,
            stride,
            steps,
            last,
            internal,
        )


#: The checksum before the first block.
_GENESIS = "0" * 64


def _block_sha(prev: str, chain_rows, lp_rows) -> str:
    """SHA-256 of a block of rows (as stored), chained to the previous block's."""
    h = hashlib.sha256(prev.encode("ascii"))
    for rows in (chain_rows, lp_rows):
        a = np.ascontiguousarray(rows)
        h.update(str(a.shape).encode("ascii"))
        h.update(a.tobytes())
    return h.hexdigest()


def _state_sha(last: str, commit: dict) -> str:
    """SHA-256 of the commit state (everything but its own checksum) onto the last
    block's."""
    state = {k: v for k, v in commit.items() if k != "state_sha256"}
    blob = json.dumps(state, sort_keys=True, allow_nan=True)
    return hashlib.sha256((last + blob).encode("utf-8")).hexdigest()


def _append_block(f, n0: int, n1: int, rows) -> tuple[int, str]:
    """Write the checksum of rows ``n0:n1`` after the committed blocks (datasets
    ``block_end``, ``block_sha``: entries beyond the commit are ignored, like rows); a
    format-2 file continued now gets its rows so far as one block. Returns the number
    of blocks and the last checksum."""
    c = json.loads(f.attrs["commit"]) if "commit" in f.attrs else {}
    if "block_sha" not in f:
        f.create_dataset("block_end", (0,), maxshape=(None,), dtype="i8", chunks=(256,))
        f.create_dataset("block_sha", (0,), maxshape=(None,), dtype="S64", chunks=(256,))
    ends, shas = f["block_end"], f["block_sha"]
    nb = int(c.get("n_blocks", 0))
    recs = list(zip(ends[:nb].astype(int).tolist(), shas[:nb], strict=True))
    prev = recs[-1][1].decode("ascii") if recs else _GENESIS
    a = recs[-1][0] if recs else 0
    if a < n0:  # rows without a block (a format-2 file): one block for them
        prev = _block_sha(prev, f["chain"][a:n0], f["log_prob"][a:n0])
        recs.append((n0, prev.encode("ascii")))
    sha = _block_sha(prev, *rows)
    recs.append((n1, sha.encode("ascii")))
    for ds in (ends, shas):
        ds.resize(len(recs), axis=0)
    ends[nb:] = [r[0] for r in recs[nb:]]
    shas[nb:] = [r[1] for r in recs[nb:]]
    return len(recs), sha


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
#: Steps per walker of the trace a compacted checkpoint keeps (the report's trace plot,
#: a few hundred pixels wide).
TRACE_STEPS = 200


def write_compact(
    path: Path, tag: str, draws, log_prob, info: dict, chain, chain_lp, row_steps: int = 1
) -> None:
    """Replace a converged chain's checkpoint by the draws its outputs use.

    ``draws`` (kept steps, walkers, d) and ``log_prob`` (kept steps, walkers) are the
    post-burn-in, thinned steps (float64: at most ``sampler.max_draws`` × d values, a
    few hundred kB); ``info`` (JSON) records the chain they came from (steps, burn,
    thin, τ, τ history, acceptance counts). ``chain``/``log_prob`` hold a trace of
    the whole chain for plots, burn-in included: every ``trace_stride``-th step
    (attribute), at most :data:`TRACE_STEPS` per walker, float32. The full chain is
    what ``--resume`` needs while a chain is unconverged; once converged, these draws
    are all a resumed run needs to rebuild its outputs. ``row_steps``: steps per row of
    ``chain`` (a thinned chain, :class:`~heritage_bayes.inference.monitor.ChainBuffer`),
    so that ``trace_stride`` counts steps. Datasets gzip-compressed with
    Fletcher-32 checksums; written atomically.
    """
    stride = max(1, -(-int(chain.shape[0]) // TRACE_STEPS))
    from heritage_bayes.inference.results import atomic_write

    def write(tmp: Path) -> None:
        with h5py.File(tmp, "w") as f:
            f.attrs["tag"] = tag
            f.attrs["format"] = COMPACT_FORMAT
            f.attrs["compact"] = json.dumps(info)
            f.attrs["trace_stride"] = stride * int(row_steps)
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
