"""Sweep backends: local worker processes and Ray give the same trials for the same seeds."""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import tempfile
import time
from pathlib import Path

import pytest

from navlab.experiments import backends
from navlab.experiments.backends import init_ray, run_tasks, wait_for_shutdown
from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import scenario_from_dict
from navlab.experiments.sweep import run_sweep
from navlab.geometry import wrap_angle

TINY = {"name": "tiny", "world": "room", "goals": [[1.2, 0.3, 0.0]], "trials": 1, "seed": 3, "time_limit": 30}


def _trials(folder: Path) -> dict[str, list[dict[str, object]]]:
    out = {}
    for f in sorted(folder.glob("*/results.jsonl")):
        rows = [json.loads(line) for line in f.read_text().splitlines()]
        for r in rows:
            r.pop("wall_s")  # the only figure that is not simulated
        out[f.parent.name] = rows
    return out


def test_ray_runs_a_sweep_with_the_same_results_as_local_workers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("RAY_ADDRESS", raising=False)  # a local Ray instance, started and stopped here
    params = {"local_costmap.update_frequency": [1.0, 5.0]}
    local = run_sweep(scenario_from_dict(TINY), params, tmp_path / "local", workers=2)
    ray = run_sweep(scenario_from_dict(TINY), params, tmp_path / "ray", workers=2, backend="ray")
    assert ray == local and all(r["success_rate"] == 1.0 for r in ray), ray
    a, b = _trials(tmp_path / "local"), _trials(tmp_path / "ray")
    assert len(a) == 2 and a == b  # every metric of every trial, bit for bit
    assert (tmp_path / "ray" / "sweep.md").read_text() == (tmp_path / "local" / "sweep.md").read_text()
    # that instance stops in the background: the next one starts once it has stopped, and stops in turn
    angles = [0.5, 7.0, -4.0]
    assert sorted(run_tasks(wrap_angle, angles, backend="ray", workers=1)) == sorted(run_tasks(wrap_angle, angles))
    wait_for_shutdown()
    import ray as ray_module

    assert not ray_module.is_initialized()


def test_an_unreachable_ray_address_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:9")
    with pytest.raises(ExperimentError, match=r"RAY_ADDRESS='127\.0\.0\.1:9' is unreachable"):
        list(run_tasks(abs, [1, -2], backend="ray"))
    monkeypatch.setenv("RAY_ADDRESS", "nonsense")
    with pytest.raises(ExperimentError, match="expected host:port"):
        list(run_tasks(abs, [1], backend="ray"))
    with pytest.raises(ExperimentError, match="backend: expected one of local, ray"):
        list(run_tasks(abs, [1], backend="dask"))


def test_a_refused_connection_names_the_cluster_and_token_authentication(monkeypatch: pytest.MonkeyPatch) -> None:
    class TokenCluster:  # a cluster that answers on its port but refuses a driver without its token
        @staticmethod
        def init(**kwargs: object) -> None:
            raise ConnectionError(f"Failed to connect to Ray cluster at {kwargs['address']}")

    with socket.create_server(("127.0.0.1", 0)) as server:
        address = f"127.0.0.1:{server.getsockname()[1]}"
        monkeypatch.setenv("RAY_ADDRESS", address)
        monkeypatch.delenv("RAY_AUTH_MODE", raising=False)
        refused = r"could not start or reach the cluster at RAY_ADDRESS=.*ConnectionError: .*RAY_AUTH_MODE=token"
        with pytest.raises(ExperimentError, match=refused):
            init_ray(TokenCluster, 2)
        monkeypatch.setenv("RAY_AUTH_MODE", "token")  # already set: no hint
        with pytest.raises(ExperimentError) as err:
            init_ray(TokenCluster, 2)
        assert "RAY_AUTH_MODE" not in str(err.value)


def test_local_workers_return_every_item_once() -> None:
    assert sorted(run_tasks(abs, [-3, 1, -2], workers=1)) == [(0, 3), (1, 1), (2, 2)]


def test_local_worker_processes_return_every_item_once_and_raise_a_trial_s_error() -> None:
    assert sorted(run_tasks(abs, [-3, 1, -2, 5, -4], workers=2)) == [(0, 3), (1, 1), (2, 2), (3, 5), (4, 4)]
    with pytest.raises(ValueError, match="math domain error") as err:
        list(run_tasks(math.sqrt, [4.0, -1.0, 9.0], workers=2))
    assert "in worker process" in "\n".join(err.value.__notes__)  # with the worker's traceback


def _stubborn(seconds: float) -> str:
    """A trial that swallows SIGTERM (as native code calling back into Python can) and writes a temporary file."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    with open(os.path.join(tempfile.mkdtemp(prefix="navlab-trial-"), "x"), "w") as f:
        f.write("x")
    time.sleep(seconds)
    status = dict(line.split(":", 1) for line in Path("/proc/self/status").read_text().splitlines())
    return status["SigIgn"].strip()


def test_closing_local_workers_ends_even_one_that_ignores_sigterm_and_removes_its_files(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C in the driver closes the generator: the workers are signalled, then killed after the grace time,
    and their temporary folders go with them (they write under a folder of the driver's)."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.setattr(backends, "STOP_GRACE_S", 2.0)
    tasks = run_tasks(_stubborn, [0.0, 120.0, 120.0], workers=2)
    i, ignored = next(tasks)
    assert i == 0 and int(ignored, 16) & (1 << (signal.SIGINT - 1))  # a worker ignores Ctrl-C (the driver's)
    t0 = time.monotonic()
    tasks.close()
    assert time.monotonic() - t0 < 6.0
    assert list(tmp_path.iterdir()) == []
