"""The replay's progress bar: one line on stderr."""

from __future__ import annotations

import math
import time
from collections import Counter
from typing import Any


class Progress:
    """Done fraction, simulated time, ETA and messages per topic, redrawn at most every
    `every_s`."""

    def __init__(self, total_s: float, stream: Any, every_s: float = 0.5) -> None:
        self.total_s, self.stream, self.every_s = max(total_s, 1e-9), stream, every_s
        self.counts: Counter[str] = Counter()
        self.started = time.monotonic()
        self.shown = 0.0

    def line(self, done_s: float, now: float) -> str:
        fraction = min(1.0, max(0.0, done_s / self.total_s))
        elapsed = now - self.started
        eta = elapsed * (1.0 - fraction) / fraction if fraction > 0 else math.inf
        bar = "#" * int(30 * fraction)
        per_topic = " ".join(f"{t}:{n}" for t, n in sorted(self.counts.items()))
        eta_text = f"{eta:5.0f} s" if math.isfinite(eta) else "    ? s"
        done = f"{100 * fraction:5.1f}% {done_s:7.1f}/{self.total_s:.1f} s"
        return f"\r[{bar:<30}] {done}  ETA {eta_text}  {per_topic}"

    def update(self, topic: str, done_s: float) -> None:
        self.counts[topic] += 1
        now = time.monotonic()
        if self.stream is not None and now - self.shown >= self.every_s:
            self.shown = now
            self.stream.write(self.line(done_s, now))
            self.stream.flush()

    def finish(self) -> None:
        if self.stream is not None:
            self.stream.write(self.line(self.total_s, time.monotonic()) + "\n")
            self.stream.flush()
