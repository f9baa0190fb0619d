"""Progress output of a calibration on stderr: lines, warnings, the sampler's bar.

A terminal gets a tqdm bar per chain; a log file (stderr not a terminal) one plain
line per update. ``--quiet`` silences everything but warnings.
"""

from __future__ import annotations

import sys

__all__ = ["Progress"]


class Progress:
    """Progress lines and warnings on stderr (see the module documentation)."""

    def __init__(self, quiet: bool):
        self.quiet = quiet
        self.bar = None

    def say(self, msg: str) -> None:
        if not self.quiet:
            print(msg, file=sys.stderr, flush=True)

    def warn(self, msg: str) -> None:
        """Shown even with --quiet."""
        print(f"hbayes: warning: {msg}", file=sys.stderr, flush=True)

    def sampler(self, label: str, max_steps: int):
        if self.quiet:
            return None
        if not sys.stderr.isatty():  # a log file: one plain line per update

            def line(done, total, info):
                self.say(
                    f"[{label}] emcee {done} steps, {info['seconds']:.0f} s: τmax "
                    f"{info['tau_max']:.0f}, need ~{total} steps, acc {info['acceptance']:.2f}"
                )

            return line
        from tqdm.auto import tqdm

        bar = tqdm(
            total=None,
            desc=f"[{label}] emcee",
            unit="step",
            file=sys.stderr,
            leave=True,
            dynamic_ncols=True,
        )

        def update(done, total, info):
            bar.total = total  # the chain's own estimate of the length it needs
            bar.n = done
            bar.set_postfix_str(
                f"τmax {info['tau_max']:.0f}, need {info['needed']:.0f} "
                f"steps, acc {info['acceptance']:.2f}"
            )
            bar.refresh()

        self.bar = bar
        return update

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None
