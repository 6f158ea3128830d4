"""The panel's rate guard on tick sequences written by hand: a loop on time is quiet; one
that misses a share of its slots is an alarm, then a stop after a bounded time; one that
stalls longer than the servos' bus watchdog is stopped at once."""

from __future__ import annotations

import pytest

from robot.panel.rate_guard import RateGuard, Verdict

RATE = 100.0  # [Hz]: slots of 10 ms


def feed(guard: RateGuard, seconds: float, *, missed_every: int = 0, t0: float = 0.0,
         overruns0: int = 0) -> tuple[list[Verdict], float, int]:
    """Ticks for ``seconds`` of loop time; every ``missed_every``-th slot is missed (the
    tick comes one slot late, and the overrun count grows by one)."""
    t, overruns, out = t0, overruns0, []
    slot = 0
    while t < t0 + seconds:
        slot += 1
        if missed_every and slot % missed_every == 0:
            t += 2 / RATE
            overruns += 1
        else:
            t += 1 / RATE
        out.append(guard.update(t, overruns))
    return out, t, overruns


def test_on_time_is_quiet() -> None:
    verdicts, _, _ = feed(RateGuard(RATE), 30.0)
    assert set(verdicts) == {Verdict()}


def test_a_few_late_ticks_are_no_alarm() -> None:
    verdicts, _, _ = feed(RateGuard(RATE), 30.0, missed_every=20)  # 1 in 21 slots: 4.8 %
    assert not any(v.alarm for v in verdicts)


def test_late_a_fifth_of_the_time_alarms_then_stops_after_late_stop_s() -> None:
    guard = RateGuard(RATE, late_stop_s=10.0)
    verdicts, _, _ = feed(guard, 15.0, missed_every=4)   # 1 missed in 5 slots: 20 %
    alarms = [k for k, v in enumerate(verdicts) if v.alarm]
    stops = [k for k, v in enumerate(verdicts) if v.stop]
    assert alarms and "ticks missed" in verdicts[alarms[0]].alarm   # type: ignore[operator]
    # The first stop comes 10 s of loop time after the first alarm (80 ticks a second).
    assert stops and (stops[0] - alarms[0]) / 80.0 == pytest.approx(10.0, abs=0.1)
    assert not verdicts[stops[0]].at_once and "safe stop" in verdicts[stops[0]].alarm  # type: ignore[operator]


def test_under_half_rate_stops_after_stop_after_s() -> None:
    guard = RateGuard(RATE, stop_after_s=2.0)
    # Every tick two slots late (one missed each): 50 % of the slots; then 2 in 3 missed.
    verdicts, t, n = feed(guard, 1.0)
    slow: list[Verdict] = []
    for _ in range(300):
        t += 3 / RATE
        n += 2
        slow.append(guard.update(t, n))
    first_alarm = next(k for k, v in enumerate(slow) if v.alarm)
    first_stop = next(k for k, v in enumerate(slow) if v.stop)
    # The stop comes 2 s after the 1-s window fell under half its rate, which is within
    # one window of the first alarm.
    assert 2.0 <= (first_stop - first_alarm) * 3 / RATE <= 2.0 + 1.0
    assert not any(v.stop for v in verdicts)


def test_a_stall_longer_than_the_servo_watchdog_stops_at_once() -> None:
    guard = RateGuard(RATE, stall_s=0.235)
    verdicts, t, n = feed(guard, 1.0)
    assert not guard.update(t + 0.2, n + 19).stop          # 200 ms: late, not stalled
    v = guard.update(t + 0.2 + 0.24, n + 43)
    assert v.stop and v.at_once and "stalled 240 ms" in (v.alarm or "")
    assert guard.update(t + 0.2 + 0.24, n + 43) == v        # the same tick: the same verdict
