"""Shared fixtures: the repository's paths and the CLI binary the bit-identity tests compare
with and the worker binary the remote-worker test starts (``COSDEM_CLI``, ``COSDEM_WORKER``; else
``target/debug/cosdem`` and ``target/debug/cosdem-worker``)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures" / "jobs"


@pytest.fixture
def fixture_job():
    """The path of a shared test job of ``fixtures/jobs``."""

    def path(name: str) -> Path:
        return FIXTURES / f"{name}.toml"

    return path


def binary(env: str, name: str, package: str) -> Path:
    path = Path(os.environ.get(env, ROOT / "target" / "debug" / name))
    assert path.exists(), f"{path}: build it first (cargo build -p {package}) or set {env}"
    return path


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `cosdem` binary."""
    return binary("COSDEM_CLI", "cosdem", "cosdem-cli")


@pytest.fixture(scope="session")
def worker_binary() -> Path:
    """The `cosdem-worker` binary."""
    return binary("COSDEM_WORKER", "cosdem-worker", "cosdem-worker-cli")
