"""Fixed-timestep clock: simulation advances in fixed steps; frame deltas are clamped."""
from __future__ import annotations

from atmos.checks import check_int, check_num


class FixedClock:
    """Turns variable frame deltas into a whole number of fixed simulation steps.

    ``max_frame_dt`` clamps one frame's delta, so a 2-second hitch counts as ``max_frame_dt`` and
    triggers no burst of catch-up steps; ``max_steps`` bounds the steps of any one frame.
    """

    def __init__(self, step: float = 1 / 30, max_frame_dt: float = 0.1, max_steps: int = 4):
        self.step = check_num("FixedClock", "step", step, 0.0, 3600.0, lo_open=True)
        self.max_frame_dt = check_num("FixedClock", "max_frame_dt", max_frame_dt, 0.0, 3600.0, lo_open=True)
        self.max_steps = check_int("FixedClock", "max_steps", max_steps, 1, 10_000)
        self.time = 0.0          # simulation time: fixed steps taken × step
        self.frame_time = 0.0    # sum of clamped frame deltas
        self.dt = 0.0            # this frame's clamped delta
        self.frame = 0
        self.steps = 0           # fixed steps taken in total
        self._accumulator = 0.0

    def advance(self, frame_dt: float) -> int:
        """Account for one frame of ``frame_dt`` seconds; return how many fixed steps to run."""
        if not frame_dt >= 0:  # negative or NaN
            frame_dt = 0.0
        self.dt = min(float(frame_dt), self.max_frame_dt)
        self.frame += 1
        self.frame_time += self.dt
        self._accumulator += self.dt
        n = min(int(self._accumulator / self.step + 1e-9), self.max_steps)
        self._accumulator = max(0.0, self._accumulator - n * self.step)
        if n == self.max_steps:
            self._accumulator = min(self._accumulator, self.step)  # drop what cannot be caught up
        return n

    def tick(self) -> None:
        """Record that one fixed step ran."""
        self.steps += 1
        self.time = self.steps * self.step

    @property
    def alpha(self) -> float:
        """How far between the last and the next fixed step this frame lies, in [0, 1)."""
        return min(self._accumulator / self.step, 0.999999)
