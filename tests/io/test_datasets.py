"""Datasets are found through NAVLAB_DATA (default ../shared/datasets beside the repository)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from navlab.errors import NavlabError
from navlab.io import DatasetNotFoundError, data_dir, dataset, datasets

REPO = Path(__file__).resolve().parents[2]


def test_navlab_data_names_the_folder(tmp_path, monkeypatch):
    (tmp_path / "mit-csail").mkdir()
    (tmp_path / "mit-csail" / "log.clf").write_text("FLASER\n")
    monkeypatch.setenv("NAVLAB_DATA", str(tmp_path))
    assert data_dir() == tmp_path
    assert dataset("mit-csail/log.clf") == tmp_path / "mit-csail" / "log.clf"


def test_relative_navlab_data_is_relative_to_the_current_directory(tmp_path, monkeypatch):
    (tmp_path / "data" / "set").mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NAVLAB_DATA", "data")
    assert dataset("set") == tmp_path / "data" / "set"


def test_default_is_shared_datasets_beside_the_checkout(tmp_path, monkeypatch):
    monkeypatch.delenv("NAVLAB_DATA", raising=False)
    monkeypatch.chdir(tmp_path)  # the checkout is found from the package, not from where we run
    assert datasets.repository_root() == REPO
    assert data_dir() == Path(os.path.normpath(REPO / ".." / "shared" / "datasets"))


def test_outside_a_checkout_the_default_is_relative_to_the_current_directory(tmp_path, monkeypatch):
    monkeypatch.delenv("NAVLAB_DATA", raising=False)
    monkeypatch.setattr(datasets, "repository_root", lambda: None)
    monkeypatch.chdir(tmp_path / ".")
    assert data_dir() == Path(os.path.normpath(tmp_path / ".." / "shared" / "datasets"))


def test_missing_dataset_says_where_it_looked_and_what_to_do(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_DATA", str(tmp_path))
    with pytest.raises(DatasetNotFoundError) as err:
        dataset("mit-csail/mit-csail.clf")
    text = str(err.value)
    assert str(tmp_path / "mit-csail" / "mit-csail.clf") in text
    assert f"NAVLAB_DATA={tmp_path}" in text and "set NAVLAB_DATA" in text and "../shared/datasets" in text
    assert isinstance(err.value, NavlabError)
    monkeypatch.delenv("NAVLAB_DATA")
    monkeypatch.setattr(datasets, "repository_root", lambda: tmp_path / "repo")
    with pytest.raises(DatasetNotFoundError, match=r"NAVLAB_DATA is unset, so the default .*shared/datasets"):
        dataset("nothing-here")


def test_absolute_dataset_path_is_refused(tmp_path):
    with pytest.raises(DatasetNotFoundError, match="relative to the datasets folder"):
        dataset(tmp_path)


def test_dataset_fixture_fails_rather_than_skips(tmp_path):
    """The tests' ``dataset`` fixture fails a test whose dataset is absent, with the message."""
    (tmp_path / "conftest.py").write_text((REPO / "conftest.py").read_text())
    (tmp_path / "test_needs_data.py").write_text("def test_x(dataset):\n    dataset('no-such-set/file.txt')\n")
    env = {**os.environ, "NAVLAB_DATA": str(tmp_path / "empty")}
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rf", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        check=False,
    )
    assert result.returncode == 1, result.stdout
    assert "1 failed" in result.stdout and "skipped" not in result.stdout
    assert "dataset no-such-set/file.txt not found at" in result.stdout and "(CI has it)" in result.stdout
