#!/usr/bin/env python3
"""rostest: MOT metrics of the tracker nodelet's output on the simulated object scene.

Pairs each published TrackedObjectArray with the simulator's truth of the same stamp and scores
them with motmetrics (0.5 m match radius): visible objects against confirmed tracks, and all
objects against every reported (confirmed or coasting) track. motmetrics comes from PyPI into
.ws/py-venv (make deps); under Debian's python3 this script re-runs itself with that venv.
"""

from __future__ import annotations

import os
import sys
import time
import unittest
from pathlib import Path

try:
    import motmetrics as mm
except ImportError:  # Debian's python3 has no motmetrics: use the project's venv
    venv_python = Path(__file__).resolve().parents[3] / ".ws" / "py-venv" / "bin" / "python"
    if venv_python.exists() and sys.executable != str(venv_python):
        os.execv(str(venv_python), [str(venv_python), *sys.argv])
    mm = None  # offline machine without PyPI: the test reports itself skipped

import numpy as np
import rospy
import rostest
from std_msgs.msg import Bool

from downstream_perception.msg import DetectedObjectArray, TrackedObjectArray


class TrackerSceneTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tracker_scene")
        if mm is None:
            raise unittest.SkipTest("motmetrics is not installed (make deps installs it)")
        cls.truth: dict[rospy.Time, DetectedObjectArray] = {}
        cls.tracks: dict[rospy.Time, TrackedObjectArray] = {}
        cls.done = False
        rospy.Subscriber(
            "/object_sim/truth",
            DetectedObjectArray,
            lambda m: cls.truth.__setitem__(m.header.stamp, m),
            queue_size=400,
        )
        rospy.Subscriber(
            "/tracker/tracks",
            TrackedObjectArray,
            lambda m: cls.tracks.__setitem__(m.header.stamp, m),
            queue_size=400,
        )

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        rospy.Subscriber("/object_sim/done", Bool, on_done, queue_size=1)
        deadline = time.time() + 100.0
        while not cls.done and time.time() < deadline and not rospy.is_shutdown():
            time.sleep(0.2)
        time.sleep(1.0)

    def test_scene_metrics_from_published_tracks(self) -> None:
        self.assertTrue(self.done, "the simulator did not finish")
        stamps = sorted(set(self.truth) & set(self.tracks))
        self.assertGreater(len(stamps), 250, "most frames must be tracked and paired")
        visible = mm.MOTAccumulator(auto_id=True)
        everything = mm.MOTAccumulator(auto_id=True)
        for stamp in stamps:
            truth = self.truth[stamp].detections
            tracks = self.tracks[stamp]
            self.assertEqual(tracks.header.frame_id, "odom")
            gt_ids = np.array([d.truth_id for d in truth])
            gt_pos = np.array([[d.position.x, d.position.y] for d in truth])
            seen = np.array([d.score > 0.5 for d in truth])
            ids = np.array([t.id for t in tracks.tracks], dtype=np.int64)
            pos = np.array([[t.position.x, t.position.y] for t in tracks.tracks]).reshape(-1, 2)
            state = np.array([t.state for t in tracks.tracks])
            conf = state == 1
            out = state != 0
            visible.update(
                gt_ids[seen],
                ids[conf],
                mm.distances.norm2squared_matrix(gt_pos[seen], pos[conf], max_d2=0.25),
            )
            everything.update(
                gt_ids, ids[out], mm.distances.norm2squared_matrix(gt_pos, pos[out], max_d2=0.25)
            )
        metrics = mm.metrics.create()
        v = metrics.compute(visible, metrics=["mota", "idf1", "num_switches"], name="v").iloc[0]
        a = metrics.compute(everything, metrics=["mota", "idf1"], name="a").iloc[0]
        rospy.loginfo("tracker scene: visible %s, all %s", v.to_dict(), a.to_dict())
        # Defaults (no tuning) through ROS, one seed (measured MOTA 0.927, IDF1 0.912, 11
        # switches, MOTA 0.949 all): bars a little below, as tf timing may differ per run.
        self.assertGreaterEqual(v["mota"], 0.90)
        self.assertGreaterEqual(v["idf1"], 0.87)
        self.assertLessEqual(v["num_switches"], 20)
        self.assertGreaterEqual(a["mota"], 0.90)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tracker_scene", TrackerSceneTest)
