"""Timers (app.after / app.every) in game time and game states (add_state, set_state, on_enter/on_exit,
in_state systems and timers), on an App without a GPU context."""
import math

import pytest

from atmos.app import App, AppError
from atmos.plugin import Plugin


@pytest.fixture
def app():
    app = App(fixed_step=0.1, max_frame_dt=0.5)
    yield app
    app.close()


def note(log, what):
    """A fn(app) that logs ``what`` with the frame time."""
    return lambda app: log.append((what, round(app.clock.frame_time, 6)))


# -- timers ----------------------------------------------------------------------------------------

def test_after_fires_once_when_its_game_time_comes(app):
    log = []
    timer = app.after(0.3, note(log, "once"))
    assert timer.active and timer.remaining == 1 and timer.due == pytest.approx(0.3)
    app.run_frames(2, 0.1)
    assert log == []
    app.run_frames(1, 0.1)                      # 0.1 * 3 is 0.30000000000000004 or 0.29999999999999993: fires
    assert log == [("once", 0.3)]
    app.run_frames(10, 0.1)
    assert log == [("once", 0.3)] and not timer.active and timer.fired == 1 and timer.remaining == 0
    assert app.timers.active == []


def test_every_repeats_on_its_period_without_drift_and_times_limits_it(app):
    log, limited = [], []
    forever = app.every(0.25, note(log, "tick"))
    three = app.every(0.1, lambda app: limited.append(app.clock.frame), times=3)
    app.run_frames(40, 1 / 60)                   # 0.6667 s: ticks at 0.25 and 0.5
    assert [t for _, t in log] == pytest.approx([0.25, 0.5], abs=1 / 60)
    assert limited == [6, 12, 18] and not three.active and three.remaining == 0
    app.run_frames(3600 - 40, 1 / 60)            # a minute at 60 fps: the period is kept exactly
    assert forever.fired == 240 and forever.due == pytest.approx(241 * 0.25) and forever.remaining is None


def test_cancel_stops_a_timer_also_inside_its_own_call(app):
    log = []
    dropped = app.after(0.1, note(log, "dropped"))
    dropped.cancel()
    dropped.cancel()                             # again: nothing

    def third_time_stops(app):
        log.append(("tick", stopper.fired))
        if stopper.fired == 3:
            stopper.cancel()
    stopper = app.every(0.1, third_time_stops)
    app.run_frames(10, 0.1)
    assert log == [("tick", 1), ("tick", 2), ("tick", 3)]
    assert stopper.cancelled and not stopper.active and "cancelled" in repr(stopper)


def test_a_timer_cancelled_by_an_earlier_call_in_the_same_frame_does_not_fire(app):
    log = []
    first = app.after(0.1, lambda app: second.cancel())
    second = app.after(0.1, note(log, "second"))
    app.run_frames(3, 0.1)
    assert first.fired == 1 and second.fired == 0 and log == []


def test_timers_fire_first_in_update_before_the_game_systems_and_the_fixed_steps(app):
    """fixed_step 0.1, frames of 0.05: the step that brings clock.time to 0.1 runs after the timer due at 0.1."""
    log = []
    app.add_system(note(log, "update"), "update", label="game_update")
    app.add_system(lambda app: log.append(("simulate", round(app.clock.time + app.clock.step, 6))), "simulate",
                   label="game_step")
    app.add_system(note(log, "last"), "last", label="game_last")
    app.after(0.1, note(log, "timer"))
    app.run_frames(2, 0.05)
    assert log == [("update", 0.05), ("last", 0.05),
                   ("timer", 0.1), ("update", 0.1), ("simulate", 0.1), ("last", 0.1)]
    assert [s.label for s in app.schedule.build()["update"]] == ["app.timers", "game_update"]


def test_a_long_frame_fires_a_repeating_timer_once_per_missed_period_in_order(app):
    """One 0.5 s frame (max_frame_dt) with a 0.1 s timer and a 0.25 s one: every period, in time order."""
    calls = []
    fast = app.every(0.1, lambda app: calls.append(("fast", round(fast.due, 6), fast.fired)))
    slow = app.every(0.25, lambda app: calls.append(("slow", round(slow.due, 6), slow.fired)))
    app.update(0.5)
    assert calls == [("fast", 0.1, 1), ("fast", 0.2, 2), ("slow", 0.25, 1), ("fast", 0.3, 3),
                     ("fast", 0.4, 4), ("fast", 0.5, 5), ("slow", 0.5, 2)]
    assert fast.due == pytest.approx(0.6) and app.clock.dt == 0.5


def test_a_hitch_counts_as_max_frame_dt_for_timers_like_for_the_simulation(app):
    log = []
    app.after(1.0, note(log, "late"))
    app.update(30.0)                             # a 30-second hitch: 0.5 s of game time
    assert log == [] and app.clock.frame_time == 0.5
    app.update(30.0)
    assert log == [("late", 1.0)]
    app.after(0.5, note(log, "paused"))
    app.run_frames(3, 0.0)                       # frames of no time: nothing comes due
    assert len(log) == 1


def test_every_catch_up_calls_stay_within_the_frame_and_times(app):
    timer = app.every(0.01, lambda app: None, times=7)
    app.update(0.5)                              # 50 periods missed, 7 allowed
    assert timer.fired == 7 and not timer.active


def test_a_timer_made_in_a_timer_call_fires_no_earlier_than_the_next_frame(app):
    log = []

    def spawn(app):
        log.append(("spawn", app.clock.frame))
        app.after(1e-12, lambda app: log.append(("child", app.clock.frame)))   # due within this frame's slack
        app.every(0.05, lambda app: log.append(("child_every", app.clock.frame)), times=2)
    app.after(0.1, spawn)
    app.update(0.1)
    assert log == [("spawn", 1)]
    app.update(0.1)                              # both children are due: they fire, in due order, in frame 2
    assert log == [("spawn", 1), ("child", 2), ("child_every", 2), ("child_every", 2)]


def test_a_timer_made_by_a_system_is_measured_from_that_frame(app):
    made = []
    app.add_system(lambda app: made.append(app.after(0.2, lambda a: None)) if not made else None, label="maker")
    app.run_frames(1, 0.1)
    assert made[0].start == pytest.approx(0.1) and made[0].due == pytest.approx(0.3)
    app.run_frames(1, 0.1)
    assert made[0].fired == 0
    app.run_frames(1, 0.1)
    assert made[0].fired == 1


def test_a_timer_call_that_raises_propagates_and_the_timer_keeps_its_count(app):
    def boom(app):
        raise KeyError("boom")
    timer = app.every(0.1, boom, times=2)
    later = app.after(0.1, lambda app: None)
    with pytest.raises(KeyError, match="boom"):
        app.update(0.1)
    assert timer.fired == 1 and timer.due == pytest.approx(0.2) and later.fired == 0
    timer.cancel()
    app.update(0.1)
    assert later.fired == 1


@pytest.mark.parametrize("make, message", [
    (lambda app: app.after(0, print), r"App\.after\.seconds must be a finite number > 0\.0, got 0"),
    (lambda app: app.after(-1.0, print), r"App\.after\.seconds must be a finite number > 0\.0, got -1\.0"),
    (lambda app: app.after(math.inf, print), r"App\.after\.seconds must be .*, got inf"),
    (lambda app: app.after(math.nan, print), r"App\.after\.seconds must be .*, got nan"),
    (lambda app: app.after("1", print), r"App\.after\.seconds must be .*, got '1'"),
    (lambda app: app.after(True, print), r"App\.after\.seconds must be .*, got True"),
    (lambda app: app.after(1.0, "print"), r"App\.after\.fn must be a callable fn\(app\), got 'print'"),
    (lambda app: app.every(0.0, print), r"App\.every\.seconds must be a finite number > 0\.0, got 0\.0"),
    (lambda app: app.every(1.0, None), r"App\.every\.fn must be a callable fn\(app\), got None"),
    (lambda app: app.every(1.0, print, times=0), r"App\.every\.times must be a whole number >= 1, or None "
                                                 r"to repeat until cancelled, got 0"),
    (lambda app: app.every(1.0, print, times=2.0), r"App\.every\.times must be .*, got 2\.0"),
    (lambda app: app.every(1.0, print, times=True), r"App\.every\.times must be .*, got True"),
    (lambda app: app.every(1.0, print, times=-3), r"App\.every\.times must be .*, got -3"),
])
def test_bad_timer_arguments_name_the_argument_and_what_is_allowed(app, make, message):
    with pytest.raises(ValueError, match=message):
        make(app)
    assert app.timers.timers == []


@pytest.mark.parametrize("use", [
    lambda app: app.after(1.0, print), lambda app: app.every(1.0, print), lambda app: app.add_state("a"),
    lambda app: app.set_state("a"), lambda app: app.on_enter("a", print), lambda app: app.on_exit("a", print),
    lambda app: app.add_system(print, in_state="a"),
], ids=["after", "every", "add_state", "set_state", "on_enter", "on_exit", "add_system"])
def test_a_closed_app_refuses_timers_and_states_with_its_usual_error(use):
    app = App()
    timer = app.after(1.0, print)
    app.close()
    timer.cancel()                               # harmless
    with pytest.raises(AppError, match=r"App\.\w+: this App was closed \(App.close\); build a new App"):
        use(app)


# -- states ----------------------------------------------------------------------------------------

def game(log=None):
    """menu -> play -> game_over, with hooks that log."""
    log = [] if log is None else log
    app = App(fixed_step=0.1, max_frame_dt=0.5).add_state("menu", "play", "game_over")
    for state in app.states.names:
        app.on_enter(state, lambda app, s=state: log.append(f"enter {s}"))
        app.on_exit(state, lambda app, s=state: log.append(f"exit {s}"))
    return app, log


def test_states_switch_at_the_end_of_the_frame_with_exit_then_enter_hooks():
    app, log = game()
    assert app.state == "menu" and log == [], "declared; entered after the startup stage"
    app.add_system(lambda app: log.append("startup"), "startup", label="startup_log")
    app.update(0.1)
    assert log == ["startup", "enter menu"]

    seen = []
    app.on_exit("menu", lambda app: seen.append(("exit sees", app.state)))
    app.on_enter("play", lambda app: seen.append(("enter sees", app.state, app.states.previous)))

    def press_start(app):
        app.set_state("play")
        log.append(f"asked in {app.state}")      # still menu for the rest of the frame
    app.add_system(press_start, "update", label="press_start", in_state="menu")
    app.add_system(lambda app: log.append(f"last in {app.state}"), "last", label="last_log")
    log.clear()
    app.update(0.1)
    assert log == ["asked in menu", "last in menu", "exit menu", "enter play"]
    assert app.state == "play" and app.states.next is None
    assert seen == [("exit sees", "menu"), ("enter sees", "play", "menu")]


def test_set_state_between_frames_takes_effect_at_the_start_of_the_next_frame():
    app, log = game()
    app.add_system(lambda app: log.append(f"update in {app.state}"), label="update_log")
    app.update(0.1)
    app.set_state("play")
    assert app.state == "menu" and app.states.next == "play"
    log.clear()
    app.update(0.1)
    assert log == ["exit menu", "enter play", "update in play"]


def test_systems_run_only_in_their_state_in_every_stage():
    app, _ = game()
    ran = []
    for stage in ("update", "simulate", "render", "last"):
        app.add_system(lambda app, s=stage: ran.append((s, app.state)), stage, label=f"play_{stage}", in_state="play")
    app.add_system(lambda app: ran.append(("always", app.state)), label="always")
    app.run_frames(2, 0.1)
    assert ran == [("always", "menu")] * 2
    ran.clear()
    app.set_state("play")
    app.update(0.1)
    assert ran == [("update", "play"), ("always", "play"), ("simulate", "play"), ("render", "play"), ("last", "play")]
    ran.clear()
    app.set_state("game_over")
    app.update(0.1)
    assert ran == [("always", "game_over")]


def test_a_gated_system_keeps_its_label_and_ordering():
    app, _ = game()
    ran = []
    app.add_system(lambda app: ran.append("b"), label="b", after="a", in_state="menu")
    app.add_system(lambda app: ran.append("a"), label="a", in_state="menu")
    app.update(0.1)
    assert ran == ["a", "b"]
    system = next(s for s in app.schedule.systems if s.label == "b")
    assert system.func.state == "menu" and "in state 'menu'" in repr(system.func)


def test_the_last_request_wins_and_the_current_state_again_restarts_it():
    app, log = game()
    app.update(0.1)
    log.clear()
    app.set_state("game_over")
    app.set_state("play")
    app.update(0.1)
    assert log == ["exit menu", "enter play"]
    log.clear()
    app.set_state("play")                        # a new round: exit and enter again
    app.update(0.1)
    assert log == ["exit play", "enter play"] and app.state == "play" and app.states.previous == "play"


def test_a_hook_that_asks_for_a_state_has_it_applied_at_the_same_boundary():
    app, log = game()
    app.on_enter("game_over", lambda app: app.set_state("menu"))     # straight back to the menu
    app.update(0.1)
    app.set_state("game_over")
    log.clear()
    app.update(0.1)
    assert log == ["exit menu", "enter game_over", "exit game_over", "enter menu"] and app.state == "menu"


def test_hooks_that_ask_for_each_other_forever_are_an_error():
    app, _ = game()
    app.on_enter("play", lambda app: app.set_state("game_over"))
    app.on_enter("game_over", lambda app: app.set_state("play"))
    app.update(0.1)
    app.set_state("play")
    with pytest.raises(RuntimeError, match=r"the state changed 100 times at one frame boundary .*hooks keep asking"):
        app.update(0.1)
    app.close()


def test_set_state_before_the_first_frame_enters_the_initial_state_first():
    app, log = game()
    app.set_state("play")
    app.update(0.1)
    assert log == ["enter menu", "exit menu", "enter play"]


def test_initial_and_an_app_without_states():
    app = App().add_state("menu", "play", initial="play")
    assert app.state == "play"
    app.close()
    plain = App()
    assert plain.state is None
    plain.run_frames(2)
    plain.close()


def test_entities_deleted_by_a_hook_are_gone_before_the_next_frame():
    from dataclasses import dataclass

    @dataclass
    class Button:
        text: str

    app, _ = game()
    button = app.world.create_entity(Button("start"))
    app.on_exit("menu", lambda app: app.world.delete_entity(button))
    seen = []
    app.add_system(lambda app: seen.append(len(app.world.get_component(Button))), label="count_buttons")
    app.update(0.1)
    app.set_state("play")
    app.update(0.1)
    assert seen == [1, 0] and not app.world.has_entity(button)


def test_state_timers_are_cancelled_when_the_state_is_left():
    app, _ = game()
    fired = []
    app.on_enter("play", lambda app: app.every(0.1, lambda app: fired.append(app.state), in_state="play"))
    app.on_enter("play", lambda app: app.after(0.5, lambda app: app.set_state("game_over"), in_state="play"))
    app.on_enter("game_over", lambda app: app.after(0.2, lambda app: app.set_state("menu")))
    app.update(0.1)
    keep = app.every(0.1, lambda app: None)     # belongs to no state: survives the changes
    app.set_state("play")
    app.run_frames(5, 0.1)
    assert fired == ["play"] * 5 and app.state == "game_over"
    app.run_frames(5, 0.1)
    assert fired == ["play"] * 5 and app.state == "menu", "the play timers stopped; game over led to the menu"
    assert [t.state for t in app.timers.active] == [None] and keep.active
    with pytest.raises(ValueError, match=r"App\.after\.in_state 'play' is not the current state 'menu'; "
                                         r"make a state's timers while in it, e.g. in app\.on_enter\('play', \.\.\.\)"):
        app.after(1.0, print, in_state="play")
    app.close()


@pytest.mark.parametrize("make, message", [
    (lambda app: app.set_state("plya"), r"App\.set_state\.name must be one of the states 'menu', 'play', "
                                        r"'game_over', got 'plya'"),
    (lambda app: app.add_system(print, in_state="pause"), r"App\.add_system\.in_state must be one of the states "
                                                          r"'menu', 'play', 'game_over', got 'pause'"),
    (lambda app: app.on_enter("Menu", print), r"App\.on_enter\.state must be one of the states .*, got 'Menu'"),
    (lambda app: app.on_exit(None, print), r"App\.on_exit\.state must be one of the states .*, got None"),
    (lambda app: app.on_enter("menu", "print"), r"App\.on_enter\.fn must be a callable fn\(app\), got 'print'"),
    (lambda app: app.every(1.0, print, in_state="over"), r"App\.every\.in_state must be one of the states .*"),
    (lambda app: app.add_state("more"), r"App\.add_state: this App's states are already declared \('menu', "
                                        r"'play', 'game_over'\); an App has one set of states"),
])
def test_unknown_states_name_the_known_ones(make, message):
    app, _ = game()
    systems = len(app.schedule.systems)
    with pytest.raises(ValueError, match=message):
        make(app)
    assert len(app.schedule.systems) == systems and app.states.next is None
    app.close()


@pytest.mark.parametrize("names, initial, message", [
    ((), None, r"App\.add_state: states must be one or more names \(non-empty strings\), got none"),
    (("menu", ""), None, r"states must be one or more names .*, got 'menu', ''"),
    (("menu", 3), None, r"states must be one or more names .*, got 'menu', 3"),
    (("menu", "play", "menu"), None, r"App\.add_state: state 'menu' is named twice; names must be unique"),
    (("menu", "play"), "pause", r"App\.add_state\.initial must be one of the states 'menu', 'play', got 'pause'"),
])
def test_bad_state_declarations(names, initial, message):
    app = App()
    with pytest.raises(ValueError, match=message):
        app.add_state(*names, initial=initial)
    assert app.state is None and app.states.names == ()
    app.close()


def test_states_must_be_declared_before_they_are_used():
    app = App()
    for use in (lambda: app.set_state("play"), lambda: app.add_system(print, in_state="play"),
                lambda: app.on_enter("play", print), lambda: app.after(1.0, print, in_state="play")):
        with pytest.raises(ValueError, match=r"=?'play', but this App has no states; declare them first with "
                                             r"app\.add_state\('menu', 'play', \.\.\.\)"):
            use()
    app.close()


class Rounds(Plugin):
    """Declares states, a gated system, a hook and a timer, then fails when asked to."""
    def __init__(self, fail):
        super().__init__()
        self.fail = fail

    def build(self, app):
        app.add_state("menu", "play")
        app.add_system(print, label="rounds_play", in_state="play")
        app.on_enter("menu", print)
        app.every(1.0, print)
        if self.fail:
            raise ValueError("Rounds: bad build")


def test_a_failed_plugin_build_takes_its_states_hooks_and_timers_out_again():
    app = App()
    systems = len(app.schedule.systems)
    with pytest.raises(ValueError, match="Rounds: bad build"):
        app.add_plugins(Rounds(fail=True))
    assert app.state is None and app.states.names == () and app.timers.timers == []
    assert len(app.schedule.systems) == systems and app.states._hooks == {"enter": {}, "exit": {}}
    app.add_plugins(Rounds(fail=False))                                # a corrected call works
    assert app.state == "menu" and len(app.timers.active) == 1
    app.close()


def test_a_start_up_that_fails_in_an_on_enter_hook_leaves_the_app_unable_to_run():
    app = App().add_state("menu")
    app.on_enter("menu", lambda app: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        app.update(0.1)
    with pytest.raises(AppError, match="start-up failed"):
        app.update(0.1)
    app.close()


def test_a_small_game_loop_menu_play_game_over():
    """The README's shape: a menu waits for start, play counts down with a timer, game over returns to the menu."""
    app = App(fixed_step=0.1, max_frame_dt=0.5).add_state("menu", "play", "game_over")
    score, states = [], []
    app.add_system(lambda app: score.append(1), "simulate", label="play_step", in_state="play")
    app.on_enter("play", lambda app: (score.clear(), app.after(1.0, lambda app: app.set_state("game_over"),
                                                                in_state="play")))
    app.on_enter("game_over", lambda app: app.after(0.5, lambda app: app.set_state("menu")))
    app.add_system(lambda app: states.append(app.state), "last", label="states_log")
    app.run_frames(2, 0.1)
    app.set_state("play")
    app.run_frames(20, 0.1)
    assert states == ["menu"] * 2 + ["play"] * 10 + ["game_over"] * 5 + ["menu"] * 5
    assert len(score) == 10, "one simulate step per play frame, counted from the round's start"
    app.close()
