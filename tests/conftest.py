"""Shared fixtures."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def experiments():
    from beadsim.study import load_experiments

    return load_experiments(ROOT / "config" / "experiments.csv")
