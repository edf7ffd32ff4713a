"""Foxglove: a client speaking the SDK's WebSocket protocol gets /map and /scan as ROS 2 CDR, and a goal it
publishes (as Foxglove's 3D panel does) reaches move_base."""

from __future__ import annotations

import json
import struct
import tempfile
import threading
import time
from pathlib import Path

from websockets.sync.client import connect

from navlab import msgs
from navlab.experiments.session import start_run
from navlab.mapping import save_true_map
from navlab.viz.foxglove_bridge import FoxgloveBridge, message_from_json

SUBPROTOCOL = "foxglove.sdk.v1"  # foxglove-sdk's name for the Foxglove WebSocket protocol


def test_foxglove_client_gets_map_and_scan_and_its_goal_reaches_move_base() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        truth = save_true_map("room_obstacles", (0, 0), Path(tmp) / "true_map.yaml")
        run = start_run("navigation", world="room_obstacles", map=str(truth))
    bridge = FoxgloveBridge(run.executor, port=0)
    thread = threading.Thread(target=lambda: run.run(600.0, quiet=True), daemon=True)
    thread.start()
    try:
        with connect(f"ws://127.0.0.1:{bridge.port}", subprotocols=[SUBPROTOCOL], open_timeout=10) as ws:
            channels: dict[str, dict[str, object]] = {}
            info = json.loads(ws.recv(timeout=10))
            assert info["op"] == "serverInfo" and "clientPublish" in info["capabilities"]
            while not {"/map", "/mybot/laser/scan"} <= set(channels):
                msg = ws.recv(timeout=10)
                if isinstance(msg, str) and json.loads(msg)["op"] == "advertise":
                    channels.update({c["topic"]: c for c in json.loads(msg)["channels"]})
            scan_ch = channels["/mybot/laser/scan"]
            assert scan_ch["encoding"] == "cdr" and scan_ch["schemaEncoding"] == "ros2msg"
            assert scan_ch["schemaName"] == "sensor_msgs/msg/LaserScan" and "float32[] ranges" in str(scan_ch["schema"])
            subs = {1: "/map", 2: "/mybot/laser/scan"}
            ws.send(
                json.dumps(
                    {
                        "op": "subscribe",
                        "subscriptions": [{"id": k, "channelId": channels[t]["id"]} for k, t in subs.items()],
                    }
                )
            )
            got: dict[str, object] = {}
            sim_times: list[int] = []
            while len(got) < 2 or not sim_times:
                msg = ws.recv(timeout=10)
                if isinstance(msg, bytes) and msg[0] == 0x02:  # time: the simulated clock
                    sim_times.append(struct.unpack_from("<Q", msg, 1)[0])
                if isinstance(msg, bytes) and msg[0] == 0x01:  # messageData: sub id, log time, payload
                    sub_id, _t = struct.unpack_from("<IQ", msg, 1)
                    topic = subs[sub_id]
                    got[topic] = msgs.TYPESTORE.deserialize_cdr(msg[13:], str(channels[topic]["schemaName"]))
            assert 0 < sim_times[-1] <= run.executor.now_ns
            assert got["/map"].info.width > 100 and len(got["/mybot/laser/scan"].ranges) > 100  # type: ignore[attr-defined]
            # publish a goal as Foxglove's 3D panel does: advertise a client channel, then binary messages
            ws.send(
                json.dumps(
                    {
                        "op": "advertise",
                        "channels": [
                            {
                                "id": 7,
                                "topic": "/move_base_simple/goal",
                                "encoding": "cdr",
                                "schemaName": "geometry_msgs/msg/PoseStamped",
                            }
                        ],
                    }
                )
            )
            time.sleep(0.3)
            goal = msgs.pose_stamped(0, "map", -1.5, 0.0, 3.14)
            ws.send(b"\x01" + struct.pack("<I", 7) + bytes(msgs.TYPESTORE.serialize_cdr(goal, msgs.type_name(goal))))
            mb = run.node("move_base")
            deadline = time.monotonic() + 10
            while (mb.handle is None or mb.handle.goal[0] != -1.5) and time.monotonic() < deadline:
                time.sleep(0.05)
            assert mb.handle is not None and mb.handle.goal == (-1.5, 0.0, mb.handle.goal[2])
            assert mb.handle.frame_id == "map" and abs(mb.handle.goal[2] - 3.14) < 1e-6
    finally:
        bridge.close()
        run.executor.stop()
        thread.join(10)


def test_json_encoded_client_messages_become_ros_messages() -> None:
    pose = message_from_json(
        "geometry_msgs/msg/PoseWithCovarianceStamped",
        {
            "header": {"frame_id": "map", "stamp": {"sec": 3, "nanosec": 5}},
            "pose": {
                "pose": {"position": {"x": 1.0, "y": 2.0}, "orientation": {"z": 1.0, "w": 0.0}},
                "covariance": [0.25] + [0.0] * 35,
            },
        },
    )
    assert msgs.pose2d(pose.pose.pose) == (1.0, 2.0, 3.141592653589793) and pose.header.frame_id == "map"
    assert msgs.stamp_ns(pose) == 3_000_000_005 and pose.pose.covariance[0] == 0.25
