"""`biped tune`'s study across worker processes: in one SQLite file (and resumed), and on a
PostgreSQL server (the several-machines path). Split from tests/test_tune.py (the search
space and the score), so that the two files run side by side."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import optuna

from robot.config.gait_file import load_gait

PY = sys.executable


def biped(*argv: str, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    return subprocess.run([PY, "-m", "robot.cli", *argv], capture_output=True, text=True,
                          timeout=timeout, check=False)


def test_two_workers_share_one_sqlite_study_and_a_rerun_resumes_it(tmp_path: Path) -> None:
    """Flat walks only (every other group skipped), 3 s each: the trials of both worker
    processes land in one study; the same command with more trials adds to it."""
    out = tmp_path / "quick.toml"
    skip = [a for g in ("slope", "cross slope", "bumps", "push*", "latency", "imu noise")
            for a in ("--skip", g)]
    argv = ["tune", "--robot", "biped12-legs", "--out", str(out), "--param", "sway",
            "--param", "Fhgt", "--seconds", "3", "--jobs", "2", *skip, "--json"]
    first = biped(*argv, "--trials", "3")
    assert first.returncode == 0, first.stderr[-2000:]
    r = json.loads(first.stdout)
    assert r["trials"] >= 3 and r["runs_per_trial"] == 1
    storage = f"sqlite:///{tmp_path / 'quick.db'}"
    study = optuna.load_study(study_name=r["study"], storage=storage)
    pids = {t.user_attrs.get("worker_pid") for t in study.trials}
    assert len(pids - {None}) == 2                         # both workers ran trials
    before = [t.params for t in study.trials]
    again = biped(*argv, "--trials", "5")
    assert again.returncode == 0, again.stderr[-2000:]
    study = optuna.load_study(study_name=r["study"], storage=storage)
    assert len(study.trials) >= 5
    assert [t.params for t in study.trials][:len(before)] == before   # resumed, not anew
    assert load_gait(str(out)).name == "quick"
    assert (tmp_path / "quick.history.png").stat().st_size > 5000


def test_two_workers_share_one_postgresql_study(tmp_path: Path) -> None:
    """The several-machines path: a PostgreSQL server (started here, Debian's binaries)
    as the storage; two worker processes put their trials into one study there."""
    from pg_server import postgres

    with postgres() as url:
        out = tmp_path / "pg.toml"
        skip = [a for g in ("slope", "cross slope", "bumps", "push*", "latency", "imu noise")
                for a in ("--skip", g)]
        r = biped("tune", "--robot", "biped12-legs", "--out", str(out), "--param", "sway",
                  "--seconds", "3", "--jobs", "2", "--trials", "3", "--storage", url,
                  "--study", "shared", *skip, "--json")
        assert r.returncode == 0, r.stderr[-2000:]
        study = optuna.load_study(study_name="shared", storage=url)
        assert len(study.trials) >= 3
        assert len({t.user_attrs.get("worker_pid") for t in study.trials} - {None}) == 2
        assert load_gait(str(out)).name == "pg"
