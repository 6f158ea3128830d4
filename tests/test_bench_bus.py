"""robot.bench.bus runs end to end and counts wire bytes exactly (no timing assertions)."""

from __future__ import annotations

from robot.bench.bus import run_bus_bench

pytest_plugins = ("bus_harness",)


def test_bench_reports_and_writes_the_protocol_minimum(protocol: str) -> None:
    r = run_bus_bench(protocol, cycles=30)
    assert r["servos"] == 18 and r["cycles"] == 30
    assert r["write_bytes_per_cycle"] == r["write_bytes_min"]
    for key in ("write_us", "raw_write_us", "write_read_us", "raw_write_read_us"):
        assert 0 < r[key]["median"] <= r[key]["p99"]
    assert r["write_ratio"] > 0 and r["write_read_ratio"] > 0
