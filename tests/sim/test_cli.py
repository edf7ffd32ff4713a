"""``navlab sim`` / ``navlab render`` and spawn specs, through the real CLI entry point."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from navlab.cli import main
from navlab.sim import SimError, parse_spawn_spec


def test_sim_verb_drives_and_summarises(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        [
            "sim",
            "--duration",
            "2",
            "--cmd-vel",
            "0.5,0",
            "--quiet",
            "--json",
            "--spawn",
            "box:name=crate,x=3,y=2,size=0.4",
            "--spawn",
            "cylinder:name=drum,x=-3,t=1",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["sim_s"] == pytest.approx(2.0)
    assert out["distance_m"] == pytest.approx(1.0, abs=0.1)  # 0.5 m/s for 2 s
    assert out["odom_pose"][0] == pytest.approx(out["true_pose"][0], abs=0.05)  # wheels slip at start
    assert {"crate", "drum"} <= set(out["models"])
    assert out["messages"]["/mybot/laser/scan"] == pytest.approx(80, abs=1)


def test_sim_verb_bad_world_is_one_line_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "--world", "no_such_world", "--duration", "0.1", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "no_such_world" in err and "Traceback" not in err


def test_spawn_specs() -> None:
    model, t = parse_spawn_spec("box:name=crate,x=2,y=-1,sx=0.2,sy=0.4,sz=0.6,static=false,mass=3,t=4.5")
    assert (model.name, model.static, t) == ("crate", False, 4.5)
    assert model.pose[:3] == (2.0, -1.0, 0.3)  # resting on the floor
    assert model.links[0].collisions[0].geometry.size == (0.2, 0.4, 0.6)
    assert model.links[0].inertial is not None and model.links[0].inertial.mass == 3.0
    with pytest.raises(SimError, match=r"radiuss.*did you mean 'radius'"):
        parse_spawn_spec("cylinder:radiuss=1")
    with pytest.raises(SimError, match="cone"):
        parse_spawn_spec("cone:x=1")
    with pytest.raises(SimError, match="x='one'"):
        parse_spawn_spec("box:x=one")


def test_render_writes_a_png(tmp_path: os.PathLike[str]) -> None:
    from sim_helpers import make_mybot, make_room

    from navlab.sim import Simulation
    from navlab.sim.render import render_image, save_png

    sim = Simulation(make_mybot(), make_room(), visuals=True)
    try:
        image = render_image(sim, width=320, height=240)
    except SimError as exc:
        pytest.skip(f"no offscreen OpenGL here: {exc}")
    assert image.shape == (240, 320, 3)
    assert image.std() > 10  # a picture, not a blank frame
    # the robot is drawn: render again without it and the images differ
    empty = render_image(Simulation(None, make_room(), visuals=True), width=320, height=240)
    assert np.abs(image.astype(int) - empty.astype(int)).sum() > 0
    path = save_png(image, os.path.join(tmp_path, "room.png"))
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 1000


def test_spawn_sdf_model_spec() -> None:
    from pathlib import Path

    model_dir = Path(__file__).parents[1] / "fixtures" / "worlds" / "models" / "l_wall"
    model, t = parse_spawn_spec(f"sdf:file={model_dir},name=wall2,x=1,y=2,yaw=0.5,t=3")
    assert (model.name, model.pose, t) == ("wall2", (1.0, 2.0, 0.0, 0.0, 0.0, 0.5), 3.0)
    assert model.static and model.links[0].collisions[0].geometry.kind == "mesh"
    with pytest.raises(SimError, match="file=PATH"):
        parse_spawn_spec("sdf:x=1")


def test_sim_verb_records_a_rosbag(tmp_path: os.PathLike[str], capsys: pytest.CaptureFixture[str]) -> None:
    from rosbags.rosbag2 import Reader

    bag = os.path.join(tmp_path, "drive")
    assert main(["sim", "--duration", "0.5", "--cmd-vel", "0.2,0", "--quiet", "--json", "--record", bag]) == 0
    out = json.loads(capsys.readouterr().out)
    with Reader(out["record"]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts["/mybot/laser/scan"] == 20 and counts["/odom"] == 15 and counts["/cmd_vel"] >= 5
