"""Launch files (args, includes, params, remaps), recording round trip, CLI tools."""

import json

import numpy as np
import pytest
import yaml

from navlab import msgs
from navlab.cli import main
from navlab.core import Context, Executor, LaunchError, Node
from navlab.core.launch import start
from navlab.core.record import Recorder
from navlab.io.rosbag import bag_graph, read_bag


def test_shipped_launch_with_args():
    s = start("talker_listener", launch_args={"rate": "10"})
    s.run(2.0)
    assert s.node("listener").heard[-1] == "Hello World: 20"


def test_include_param_file_and_remap(tmp_path):
    (tmp_path / "p.yaml").write_text("rate: 4.0\n")
    (tmp_path / "inner.launch.yaml").write_text(
        "launch:\n- arg: {name: topic}\n"
        "- node: {pkg: navlab, exec: listener, name: ears, remap: [{from: chatter, to: $(var topic)}]}\n"
    )
    (tmp_path / "outer.launch.yaml").write_text(
        "launch:\n- arg: {name: t, default: /talk}\n"
        "- node: {pkg: navlab, exec: talker, name: mouth, param: [{from: p.yaml}],"
        " remap: [{from: chatter, to: /talk}]}\n"
        "- include: {file: inner.launch.yaml, arg: [{name: topic, value: $(var t)}]}\n"
    )
    s = start(str(tmp_path / "outer.launch.yaml"))
    s.run(1.0)
    assert len(s.node("ears").heard) == 4
    assert "/talk" in s.executor.topics and "/chatter" not in s.executor.topics


def test_if_and_unless(tmp_path):
    f = tmp_path / "c.launch.yaml"
    f.write_text(
        "launch:\n- arg: {name: talk, default: 'false'}\n"
        "- node: {if: $(var talk), pkg: navlab, exec: talker, name: t}\n"
        "- node: {unless: $(var talk), pkg: navlab, exec: listener, name: l}\n"
    )
    assert list(start(str(f)).nodes) == ["/l"]
    assert list(start(str(f), talk="true").nodes) == ["/t"]


def test_launch_errors(tmp_path):
    with pytest.raises(LaunchError, match="shipped launches"):
        start("no_such_launch")
    f = tmp_path / "x.launch.yaml"
    f.write_text("launch:\n- node: {pkg: navlab, exec: tlker}\n")
    with pytest.raises(LaunchError, match="unknown node executable 'tlker'"):
        start(str(f))
    f.write_text("launch:\n- arg: {name: needed}\n")
    with pytest.raises(LaunchError, match="needed:=VALUE"):
        start(str(f))


def test_recording_round_trip(tmp_path):
    ex = Executor(seed=3)
    node = Node("odom_pub", context=Context(ex))
    pub = node.create_publisher(msgs.Odometry, "odom")
    scan_pub = node.create_publisher(msgs.LaserScan, "scan")
    sent = []

    def tick() -> None:
        t = ex.now_ns
        m = msgs.Odometry(
            header=msgs.header(t, "odom"),
            child_frame_id="chassis",
            pose=msgs.PoseWithCovariance(pose=msgs.pose_from_2d(t / 1e9, 0.5, 0.1), covariance=msgs.covariance((1, 2))),
            twist=msgs.TwistWithCovariance(twist=msgs.twist(0.3, 0.1), covariance=msgs.covariance()),
        )
        pub.publish(m)
        sent.append((t, m))
        scan_pub.publish(
            msgs.LaserScan(
                header=msgs.header(t, "laser"),
                angle_min=-1.0,
                angle_max=1.0,
                angle_increment=0.5,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.2,
                range_max=25.0,
                ranges=node.rng.random(5).astype("float32"),
                intensities=np.zeros(0, "float32"),
            )
        )

    node.create_timer(0.1, tick)
    bag = tmp_path / "run"
    rec = Recorder(ex, bag, topics=["/odom"])
    ex.run(1.0)
    rec.close()
    # the files inside carry the bag's final name, and no staging folder is left behind
    assert sorted(f.name for f in bag.iterdir()) == ["metadata.yaml", "run.mcap"]
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["relative_file_paths"] == ["run.mcap"]
    assert [f.name for f in tmp_path.iterdir()] == ["run"]
    got = list(read_bag(bag))
    assert [t for _, t, _ in got] == [t for t, _ in sent]
    for (_, _, a), (_, b) in zip(got, sent, strict=True):
        assert a.pose.pose.position.x == b.pose.pose.position.x
        assert a.twist.twist.linear.x == 0.3 and list(a.pose.covariance[:8]) == list(b.pose.covariance[:8])
    assert {topic for topic, _, _ in got} == {"/odom"}
    assert "/odom_pub" in bag_graph(bag)["nodes"]


def test_recording_keeps_latched_messages_published_before_it_started(tmp_path):
    ex = Executor()
    node = Node("map_server", context=Context(ex))
    node.create_publisher(msgs.String, "map", latched=True).publish(msgs.String(data="the map"))
    node.send_static_transform(msgs.transform_stamped(0, "chassis", "laser", 0.1, 0.0, 0.0))
    Node("robot_state_publisher", context=Context(ex)).send_static_transform(
        msgs.transform_stamped(0, "chassis", "imu", 0, 0, 0)
    )
    with Recorder(ex, tmp_path / "bag"):
        ex.run(0.5)
    got = list(read_bag(tmp_path / "bag"))
    assert [m.data for topic, _, m in got if topic == "/map"] == ["the map"]
    statics = {m.transforms[0].child_frame_id for topic, _, m in got if topic == "/tf_static"}
    assert statics == {"laser", "imu"}  # every latched publisher's message, not only the last one


def test_cli_topic_hz_and_graph(tmp_path, capsys):
    assert main(["topic", "hz", "/chatter", "--json", "--launch", "talker_listener", "rate:=20"]) == 0
    hz = json.loads(capsys.readouterr().out)
    assert hz["average_rate_hz"] == pytest.approx(20.0)
    assert main(["graph", "--launch", "talker_listener", "--out", str(tmp_path / "g")]) == 0
    dot = (tmp_path / "g" / "graph.dot").read_text()
    assert '"n:/talker" -> "t:/chatter"' in dot and '"t:/chatter" -> "n:/listener"' in dot
    assert (tmp_path / "g" / "graph.svg").read_text().lstrip().startswith("<?xml")


def test_cli_error_is_one_line(capsys):
    assert main(["launch", "missing_launch", "--duration", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("navlab: error: no launch file") and "Traceback" not in err


def test_cli_usage_errors_are_one_line(capsys):
    bad = (["launch", "sim", "--duration", "x"], ["launch", "sim", "--duration", "-1"], ["sim", "--duration", "-1"])
    for argv in (*bad, ["no_such_verb"]):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("navlab: error: ") and err.count("\n") == 1, err
    assert main(["launch", "sim", "wrold:=room", "--duration", "1"]) == 2
    assert "unknown launch argument 'wrold' (did you mean 'world'?" in capsys.readouterr().err


def test_every_verb_documents_itself():
    import argparse

    from navlab.cli import build_parser

    def walk(p: argparse.ArgumentParser) -> list[str]:
        gaps = [] if (p.description or "").strip() else [f"{p.prog}: no description"]
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for sp in a.choices.values():
                    gaps += walk(sp)
            elif not isinstance(a, argparse._HelpAction) and not (a.help or "").strip():
                gaps.append(f"{p.prog}: {a.option_strings or a.dest} has no help")
        return gaps

    assert walk(build_parser()) == []


def test_launch_show_args(capsys):
    assert main(["launch", "localization", "--show-args"]) == 0
    out = capsys.readouterr().out
    assert "'map':" in out and "(required)" in out and "(default: 'room')" in out
    assert not [line for line in out.splitlines() if line.count("(default:") > 1]  # said once, in words if given
