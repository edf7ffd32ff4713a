"""Parameter files (ROS 1 and Nav2 layouts), typed declarations, did-you-mean, malformed YAML."""

import re

import pytest

from navlab.core import Context, Executor, Node, ParameterError, load_params, read_params

ROS1 = """\
controller_frequency: 5.0
TrajectoryPlannerROS:
  max_vel_x: 0.45
  min_vel_x: 0.1
global_costmap:
  update_frequency: 2
  inflation_radius: 0.55
"""

NAV2 = """\
amcl:
  ros__parameters:
    min_particles: 500
    max_particles: 2000
    laser_model_type: likelihood_field
controller_server:
  ros__parameters:
    controller_frequency: 20.0
"""


class Planner(Node):
    def __init__(self, ex: Executor, **kw):
        super().__init__("move_base", context=Context(ex), **kw)
        self.freq = self.declare_parameter("controller_frequency", 20.0).value
        self.max_vel = self.declare_parameter("TrajectoryPlannerROS/max_vel_x", 0.5).value
        self.min_vel = self.declare_parameter("TrajectoryPlannerROS.min_vel_x", 0.1).value
        self.upd = self.declare_parameter("global_costmap/update_frequency", 5.0).value
        self.infl = self.declare_parameter("global_costmap/inflation_radius", 0.55).value


def test_ros1_layout(tmp_path):
    f = tmp_path / "move_base.yaml"
    f.write_text(ROS1)
    node = Planner(Executor(), parameters=load_params(f))
    assert (node.freq, node.max_vel, node.upd) == (5.0, 0.45, 2.0)
    assert isinstance(node.upd, float)
    node.check_parameters()


def test_nav2_layout(tmp_path):
    f = tmp_path / "nav2.yaml"
    f.write_text(NAV2)
    p = load_params(f, node="amcl")
    assert p == {"min_particles": 500, "max_particles": 2000, "laser_model_type": "likelihood_field"}
    assert set(load_params(f)) == {"amcl", "controller_server"}
    with pytest.raises(ParameterError, match="no parameters for node 'bt_navigator'"):
        load_params(f, node="bt_navigator")


def test_unknown_key_did_you_mean():
    node = Planner(Executor(), parameters={"controller_frequncy": 3.0})
    with pytest.raises(ParameterError, match="did you mean 'controller_frequency'"):
        node.check_parameters()


def test_unknown_key_refused_when_run_starts():
    ex = Executor()
    Planner(ex, parameters={"TrajectoryPlannerROS": {"max_vel_xx": 1.0}})
    with pytest.raises(ParameterError, match=r"TrajectoryPlannerROS\.max_vel_x"):
        ex.run(0.1)


def test_wrong_type_is_refused():
    with pytest.raises(ParameterError, match="controller_frequency"):
        Planner(Executor(), parameters={"controller_frequency": "fast"})


def test_malformed_yaml_names_file_and_line(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("a: 1\nb: [1, 2\nc: 3\n")
    with pytest.raises(ParameterError, match=r"bad\.yaml:\d+:\d+: malformed YAML"):
        load_params(f)


def test_swapped_letters_of_a_short_name_are_a_typo_not_an_ignored_key():
    # difflib rates lsimga / lsigma at 0.83, under the typo cutoff: the swap would have been dropped silently
    from navlab.mapping import MappingError
    from navlab.mapping.gmapping import GMappingParams

    with pytest.raises(MappingError, match="did you mean 'lsigma'"):
        read_params(GMappingParams, {"lsimga": 0.1})


def test_one_reader_for_settings_dataclasses(caplog) -> None:  # type: ignore[no-untyped-def]
    """read_params: aliases, ignored keys, typed values, ranges, choices, ROS's clamp with a warning, the unknown-key
    policy (a typo raises with "did you mean", another key warns), then validate()."""
    import dataclasses
    from typing import ClassVar

    from navlab.core.params import ParameterWarning, ParamSpec

    @dataclasses.dataclass
    class Demo:
        max_vel_x: float = 0.5
        samples: int = 3
        mode: str = "both"
        flag: bool = False
        PARAMS: ClassVar[ParamSpec] = ParamSpec(
            "demo_planner",
            aliases={"max_trans_vel": "max_vel_x"},
            ignored=frozenset({"use_sim_time"}),
            above={"max_vel_x": 0.0},
            choices={"mode": ("local", "both")},
            clamp_at_least={"samples": 1},
        )

        def validate(self) -> None:
            if self.flag and self.mode == "local":
                raise ParameterError("demo_planner parameters flag and mode 'local' cannot go together")

    got = read_params(Demo, {"max_trans_vel": 1, "samples": 2.0, "flag": 1, "use_sim_time": True})
    assert (got.max_vel_x, got.samples, got.flag) == (1.0, 2, True) and isinstance(got.max_vel_x, float)
    with caplog.at_level("WARNING"):
        assert read_params(Demo, {"samples": 0}).samples == 1
    assert "samples is 0; it is set to 1" in caplog.text
    for values, words in [
        ({"max_trans_vel": 1.0, "max_vel_x": 2.0}, "two spellings of one parameter"),
        ({"max_vel_x": "fast"}, "demo_planner parameter max_vel_x: expected a number, got 'fast'"),
        ({"samples": 2.5}, "samples: expected an integer, got 2.5"),
        ({"flag": "yes"}, "flag: expected true or false"),
        ({"max_vel_x": float("nan")}, "max_vel_x: expected a finite number"),
        ({"max_vel_x": 0.0}, "max_vel_x: expected > 0.0, got 0.0"),
        ({"mode": "global"}, "mode: expected one of 'local', 'both', got 'global'"),
        ({"max_vel_xx": 1.0}, "unknown demo_planner parameter 'max_vel_xx'; did you mean 'max_vel_x'?"),
        ({"flag": True, "mode": "local"}, "cannot go together"),
        ([1, 2], "expected a dict of ROS parameters, got list"),
    ]:
        with pytest.raises(ParameterError, match=re.escape(words)):
            read_params(Demo, values)
    with pytest.warns(ParameterWarning, match="unknown demo_planner parameter 'meter_scoring' ignored"):
        assert read_params(Demo, {"meter_scoring": True}) == Demo()
