"""Fixtures shared by every test folder (here at the repository root, not in tests/, so that the test
folders' own ``from conftest import ...`` stay the only first-party ``conftest`` for ruff's import sorting)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from navlab.io.datasets import dataset as find_dataset
from navlab.io.errors import DatasetNotFoundError


@pytest.fixture
def dataset() -> Callable[[str], Path]:
    """``dataset("mit-csail/mit-csail.clf")`` -> its path under ``NAVLAB_DATA``; a missing dataset FAILS
    the test with a message saying where to put it (CI has the datasets, so a silent skip would hide a
    broken setup)."""

    def find(relpath: str) -> Path:
        try:
            return find_dataset(relpath)
        except DatasetNotFoundError as exc:
            pytest.fail(f"{exc} (CI has it)", pytrace=False)

    return find
