"""Issue 23: ROS 1 XML .launch files read with roslaunch's semantics (core/roslaunch.py), and the nodes
navlab does not implement started as processes as roslaunch starts them (core/processes.py)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from navlab.core import LaunchError
from navlab.core.launch import start
from navlab.core.roslaunch import load

WS = Path(__file__).parents[1] / "fixtures" / "ros_ws"


@pytest.fixture(autouse=True)
def _workspace(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(WS))


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_roslaunch_semantics(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """args, params (types, textfile via rosparam), groups, includes with args and ns, remaps, env, substitutions."""
    monkeypatch.setenv("NAVLAB_T_ENV", "from-env")
    monkeypatch.delenv("NAVLAB_T_UNSET", raising=False)
    _write(tmp_path / "cfg.yaml", "gain: 2\nnested: {a: 1, b: [1, 2]}\nname: $(arg robot)\n")
    _write(
        tmp_path / "inc.launch",
        """<launch>
  <arg name="speed"/>
  <arg name="fixed" value="F"/>
  <param name="speed" value="$(arg speed)"/>
  <node pkg="p" type="t" name="inner"><param name="here" value="$(dirname)"/></node>
</launch>""",
    )
    top = _write(
        tmp_path / "top.launch",
        """<launch>
  <arg name="robot" default="r1"/>
  <arg name="use_group" default="true"/>
  <arg name="count" default="3"/>
  <param name="/global/int" value="7"/>
  <param name="float" value="1.5"/>
  <param name="text" type="str" value="7"/>
  <param name="flag" value="True"/>
  <param name="yaml" type="yaml" value="[1, 2]"/>
  <param name="env" value="$(env NAVLAB_T_ENV) $(optenv NAVLAB_T_UNSET fallback words)"/>
  <param name="pkg" value="$(find my_slam)"/>
  <param name="anon1" value="$(anon worker)"/>
  <param name="anon2" value="$(anon worker)"/>
  <rosparam file="$(dirname)/cfg.yaml" ns="loaded" subst_value="true"/>
  <rosparam ns="loaded" command="delete" param="nested/a"/>
  <rosparam param="list">[3, 4]</rosparam>
  <remap from="cmd_vel" to="/base/cmd_vel"/>
  <group ns="robots" if="$(arg use_group)">
    <remap from="scan" to="base_scan"/>
    <env name="GROUP_ENV" value="g"/>
    <node pkg="p" type="t" name="driver" args="-a 1" respawn="true" required="false">
      <param name="~private" value="1"/>
      <param name="rel" value="2"/>
      <rosparam>{tuned: {k: 0.5}}</rosparam>
      <remap from="odom" to="wheel_odom"/>
    </node>
    <include file="$(dirname)/inc.launch" ns="sub"><arg name="speed" value="0.3"/></include>
  </group>
  <group unless="$(arg use_group)"><node pkg="p" type="t" name="never"/></group>
</launch>""",
    )
    config = load([top], {"robot": "r2"})
    p = config.params
    assert p["/global/int"] == 7 and p["/float"] == 1.5 and p["/text"] == "7" and p["/flag"] is True
    assert p["/yaml"] == [1, 2]
    assert p["/env"] == "from-env fallback words"
    assert p["/pkg"] == str((WS / "my_slam").resolve())
    assert p["/anon1"] == p["/anon2"] and p["/anon1"].startswith("worker_")
    assert p["/loaded/gain"] == 2 and p["/loaded/name"] == "r2" and p["/loaded/nested/b"] == [1, 2]
    assert "/loaded/nested/a" not in p  # rosparam delete
    assert p["/list"] == [3, 4]
    assert p["/robots/driver/private"] == 1 and p["/robots/driver/rel"] == 2
    assert p["/robots/driver/tuned/k"] == 0.5
    assert p["/robots/sub/speed"] == 0.3 and p["/robots/sub/inner/here"] == str(tmp_path)
    nodes = {n.fqn: n for n in config.nodes}
    assert set(nodes) == {"/robots/driver", "/robots/sub/inner"}
    driver = nodes["/robots/driver"]
    assert driver.remaps == [("cmd_vel", "/base/cmd_vel"), ("scan", "base_scan"), ("odom", "wheel_odom")]
    assert driver.env == {"GROUP_ENV": "g"} and driver.args == "-a 1" and driver.respawn and not driver.required
    assert config.params_under("/robots/driver") == {"private": 1, "rel": 2, "tuned": {"k": 0.5}}


@pytest.mark.parametrize(
    ("body", "args", "message"),
    [
        ('<arg name="speed" default="1"/>', {"sped": "2"}, "unknown launch argument 'sped' (did you mean 'speed'?"),
        ('<arg name="speed"/><param name="s" value="$(arg speed)"/>', {}, "arg 'speed' is not set; pass speed:=VALUE"),
        ('<arg name="speed" value="1"/>', {"speed": "2"}, "cannot override arg 'speed'"),
        ('<param name="s" value="$(arg nope)"/>', {}, "arg 'nope' is not defined"),
        ('<param name="s" value="$(env NAVLAB_T_UNSET)"/>', {}, "environment variable 'NAVLAB_T_UNSET' is not set"),
        ('<param name="s" value="$(find no_such_pkg)"/>', {}, "ROS package 'no_such_pkg' not found"),
        ('<param name="s" command="ls /"/>', {}, "runs a program; navlab runs programs named by a launch file only"),
        ('<group if="maybe"/>', {}, "'maybe' is not a boolean"),
        ('<nodes pkg="a" type="b" name="c"/>', {}, "unknown tag <nodes>; did you mean <node>?"),
        ('<node pkg="a" type="b" name="c"/><node pkg="a" type="b" name="c"/>', {}, "already in this launch"),
        ('<param name="s" value="x $(eval 1 + 1)"/>', {}, "must be the whole attribute"),
        ('<include file="$(dirname)/inc.launch"><arg name="bogus" value="1"/></include>', {}, "unused args [bogus]"),
    ],
)
def test_bad_launch_files_get_one_clear_error(
    tmp_path: Path, body: str, args: dict[str, str], message: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("NAVLAB_T_UNSET", raising=False)
    _write(tmp_path / "inc.launch", "<launch/>")
    file = _write(tmp_path / "bad.launch", f"<launch>{body}</launch>")
    with pytest.raises(LaunchError) as err:
        load([file], args)
    assert message in str(err.value) and str(file.parent) in str(err.value)


def test_eval_runs_in_the_sandbox(tmp_path: Path) -> None:
    file = _write(
        tmp_path / "e.launch",
        """<launch>
  <arg name="radius" default="0.5"/>
  <param name="twice" value="$(eval 2 * float(radius))"/>
  <param name="picked" value="$(eval arg('radius') == '0.5')"/>
  <group if="$(eval float(radius) &gt; 0.4 and optenv('NAVLAB_T_UNSET', 'x') == 'x')">
    <param name="big" value="$(eval find('my_slam').endswith('my_slam'))"/>
  </group>
</launch>""",
    )
    config = load([file], {})
    assert config.params["/twice"] == 1.0 and config.params["/picked"] is True and config.params["/big"] is True
    bad = _write(tmp_path / "b.launch", '<launch><param name="x" value="$(eval __import__(\'os\'))"/></launch>')
    with pytest.raises(LaunchError, match=r"\$\(eval __import__"):
        load([bad], {})


def _recorded(path: Path, timeout: float = 20.0) -> dict:
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, "the process never wrote its record"
        time.sleep(0.05)
    return json.loads(path.read_text())


def test_unknown_node_starts_as_a_process_with_the_ros_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    monkeypatch.setenv("ROS_MASTER_URI", "http://localhost:11999")
    out = tmp_path / "record.json"
    session = start(WS / "my_tools" / "launch" / "record.launch", ros=True, launch_args={"out": str(out)})
    try:
        rec = _recorded(out)
    finally:
        session.shutdown()
    argv = rec["argv"]
    assert Path(argv[0]) == (WS / "my_tools" / "scripts" / "recorder").resolve()
    assert argv[1:4] == ["--rate", "5", "two words"]
    assert argv[4:6] == ["chatter:=/talk", "scan:=base_scan"]
    assert argv[6] == "__name:=rec" and argv[7].startswith("__log:=") and argv[7].endswith("robot1-rec-1.log")
    assert rec["env"]["ROS_MASTER_URI"] == "http://localhost:11999"
    assert rec["env"]["ROS_NAMESPACE"] == "/robot1"
    assert rec["cwd"] == str(tmp_path / "ros_home")
    assert session.processes is None  # shut down


def test_a_required_process_that_exits_stops_the_launch(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    out = tmp_path / "record.json"
    session = start(
        WS / "my_tools" / "launch" / "record.launch", launch_args={"out": str(out), "exit_code": "0", "ros": "true"}
    )
    try:
        _recorded(out)
        deadline = time.monotonic() + 20
        while not session.executor.stopped and time.monotonic() < deadline:
            session.run(0.1)  # the executor handles the posted stop between events
            time.sleep(0.02)
        assert session.executor.stopped
    finally:
        session.shutdown()


def test_without_the_bridge_an_unknown_node_is_named_not_run(tmp_path: Path) -> None:
    out = tmp_path / "record.json"
    session = start(WS / "my_tools" / "launch" / "record.launch", launch_args={"out": str(out)})
    session.run(0.2)
    assert not out.exists() and session.processes is None
    (note,) = [n for n in session.notes if "/robot1/rec" in n]
    assert "my_tools/recorder" in note and "ros:=true" in note


def test_an_unknown_harmless_key_warns_naming_the_parameter_file(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    _write(tmp_path / "amcl_params.yaml", "min_particles: 200\nuse_map_topic: true\nfancy_new_option: 3\n")
    file = _write(
        tmp_path / "amcl.launch",
        """<launch>
  <node pkg="amcl" type="amcl" name="amcl"><rosparam file="$(dirname)/amcl_params.yaml" command="load"/></node>
</launch>""",
    )
    with caplog.at_level("WARNING", logger="navlab.launch"):
        session = start(file)
    assert session.node("amcl").get_parameter("min_particles") == 200
    (msg,) = [r.getMessage() for r in caplog.records if "fancy_new_option" in r.getMessage()]
    assert msg.startswith("amcl_params.yaml: ")
