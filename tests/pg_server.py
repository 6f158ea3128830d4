"""A throwaway PostgreSQL server for tests: Debian's server binaries (make test installs
the package), a new cluster in a temporary directory, listening on a Unix socket only.
As root the cluster runs as the ``postgres`` user (initdb refuses root)."""

from __future__ import annotations

import glob
import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def server_bin(name: str) -> str:
    """The path of a PostgreSQL server program (initdb, pg_ctl, ...)."""
    found = sorted(glob.glob(f"/usr/lib/postgresql/*/bin/{name}"))
    if found:
        return found[-1]
    path = shutil.which(name)
    if path is None:
        raise FileNotFoundError(f"PostgreSQL's {name} not found: install Debian's "
                                "postgresql package (make test does)")
    return path


@contextmanager
def postgres(*, port: int = 54329) -> Iterator[str]:
    """Start a server; yield a SQLAlchemy URL of an empty database; stop it. Its files
    live in a new directory under /tmp (not the test's own tmp_path: as root, that one's
    parents are private to root and the postgres user could not reach them)."""
    tmp = Path(tempfile.mkdtemp(prefix="biped-pg-"))
    try:
        yield from _serve(tmp, port)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _serve(tmp: Path, port: int) -> Iterator[str]:
    data, sock = tmp / "pgdata", tmp / "pgsock"
    sock.mkdir()
    as_user: list[str] = []
    user = os.environ.get("USER", "postgres")
    if os.geteuid() == 0:
        as_user = ["runuser", "-u", "postgres", "--"]
        user = "postgres"
        shutil.chown(tmp, "postgres")
        shutil.chown(sock, "postgres")

    def run(*cmd: str) -> None:
        subprocess.run([*as_user, *cmd], check=True, capture_output=True, text=True,
                       timeout=120)
    run(server_bin("initdb"), "-D", str(data), "-A", "trust", "-U", user)
    run(server_bin("pg_ctl"), "-D", str(data), "-w", "-l", str(tmp / "pg.log"), "-o",
        f"-p {port} -k {sock} -c listen_addresses=''", "start")
    try:
        run(server_bin("createdb") if glob.glob("/usr/lib/postgresql/*/bin/createdb")
            else "createdb", "-h", str(sock), "-p", str(port), "-U", user, "biped_tune")
        yield f"postgresql+psycopg2://{user}@/biped_tune?host={sock}&port={port}"
    finally:
        run(server_bin("pg_ctl"), "-D", str(data), "-w", "-m", "fast", "stop")
