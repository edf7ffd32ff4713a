"""rosbag2 writing and reading without an executor (``BagWriter``, ``read_bag``, ``bag_topics``)."""

from __future__ import annotations

import json

import pytest

from navlab import msgs
from navlab.io import BagError, IoError
from navlab.io.rosbag import GRAPH_KEY, BagWriter, bag_graph, bag_topics, read_bag


def test_written_messages_read_back_in_order_with_types_and_custom_data(tmp_path):
    bag = tmp_path / "log"
    with BagWriter(bag) as w:
        for k in range(5):
            w.write("/chatter", msgs.String(data=f"hello {k}"), 1_000_000 * k)
            w.write("/cmd_vel", msgs.twist(0.1 * k, -0.2), 1_000_000 * k + 500)
        w.set_custom_data(GRAPH_KEY, json.dumps({"nodes": ["/talker"], "topics": {}}))
        assert not bag.exists()  # staged until closed
    assert w.count == 10
    assert sorted(f.name for f in bag.iterdir()) == ["log.mcap", "metadata.yaml"]
    assert [f.name for f in tmp_path.iterdir()] == ["log"]  # no staging folder left
    got = list(read_bag(bag))
    assert [t for _, t, _ in got] == sorted(t for _, t, _ in got)
    assert [m.data for topic, _, m in got if topic == "/chatter"] == [f"hello {k}" for k in range(5)]
    assert [m.linear.x for topic, _, m in got if topic == "/cmd_vel"] == pytest.approx([0.1 * k for k in range(5)])
    assert bag_topics(bag) == {"/chatter": ("std_msgs/msg/String", 5), "/cmd_vel": ("geometry_msgs/msg/Twist", 5)}
    assert bag_graph(bag) == {"nodes": ["/talker"], "topics": {}}
    assert [m.data for _, _, m in read_bag(bag, topics=["/chatter"])][:1] == ["hello 0"]


def test_existing_target_and_unreadable_bags_are_errors(tmp_path):
    (tmp_path / "taken").mkdir()
    with pytest.raises(BagError, match="already exists"):
        BagWriter(tmp_path / "taken")
    with pytest.raises(IoError, match="no such rosbag2 directory"):
        list(read_bag(tmp_path / "missing"))
    with pytest.raises(BagError, match=r"damaged recording: metadata\.yaml"):
        bag_graph(tmp_path / "taken")
