import pytest

from atmos.app import App
from atmos.clock import FixedClock


def test_fixed_steps_accumulate():
    clock = FixedClock(step=0.1, max_frame_dt=1.0, max_steps=10)
    assert [clock.advance(0.04) for _ in range(5)] == [0, 0, 1, 0, 1]


def test_hitch_does_not_burst():
    clock = FixedClock(step=1 / 30, max_frame_dt=0.1, max_steps=4)
    for _ in range(10):
        clock.advance(1 / 30)
    steps = clock.advance(2.0)                 # a 2-second hitch
    assert steps <= 3 and clock.dt == pytest.approx(0.1)
    assert [clock.advance(1 / 30) for _ in range(3)] in ([1, 1, 1], [1, 1, 2], [2, 1, 1], [1, 2, 1])


def test_simulate_stage_runs_once_per_fixed_step():
    app = App(fixed_step=0.05, max_frame_dt=0.5)
    count = []
    app.add_system(lambda app: count.append(app.clock.dt), "simulate", label="count")
    app.run_frames(10, dt=0.025)            # 0.25 s -> 5 steps
    assert len(count) == 5 and app.clock.time == pytest.approx(0.25)
    app.close()


@pytest.mark.parametrize("dt", [-1.0, float("nan"), 0.0])
def test_bad_frame_delta_advances_nothing(dt):
    clock = FixedClock()
    assert clock.advance(dt) == 0 and clock.dt == 0.0


@pytest.mark.parametrize("kwargs, message", [
    (dict(step=0), r"FixedClock.step must be a finite number > 0.0 and <= 3600.0, got 0"),
    (dict(step=float("inf")), r"FixedClock.step must be .*, got inf"),
    (dict(step="fast"), r"FixedClock.step must be .*, got 'fast'"),
    (dict(max_frame_dt=float("nan")), r"FixedClock.max_frame_dt must be .*, got nan"),
    (dict(max_steps=1.5), r"FixedClock.max_steps must be a whole number 1..10000, got 1.5"),
    (dict(max_steps=float("inf")), r"FixedClock.max_steps must be a whole number 1..10000, got inf"),
])
def test_bad_clock_parameters(kwargs, message):
    with pytest.raises(ValueError, match=message):
        FixedClock(**kwargs)
