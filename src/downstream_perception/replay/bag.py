"""What a bag holds, read once before anything starts, and whether it can feed the pipeline."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from downstream_perception.replay.pipeline import Pipeline, ReplayError

TF_TOPICS = ("/tf", "/tf_static")
# A /tf stamp that goes back by more than this for the same child frame is a clock jump (a looped
# bag, a restarted simulator), not reordering.
CLOCK_JUMP_S = 1.0


@dataclass
class BagSummary:
    path: Path
    start_s: float
    end_s: float
    topics: dict[str, tuple[str, int]]  # topic -> (type, count)
    frames: dict[str, str] = field(default_factory=dict)  # input topic -> its header frame_id
    tf_parents: dict[str, str] = field(default_factory=dict)  # child -> parent, /tf and /tf_static
    clock_jumps: list[str] = field(default_factory=list)
    transform_ages_s: dict[str, list[float]] = field(default_factory=dict)
    input_stamps_s: dict[str, list[float]] = field(default_factory=dict)  # parallel to the ages

    @property
    def duration_s(self) -> float:
        return max(0.0, self.end_s - self.start_s)

    @property
    def messages(self) -> int:
        return sum(n for _, n in self.topics.values())


def open_bag(path: Path) -> Any:
    import rosbag

    if not path.is_file():
        raise ReplayError(f"{path}: no such file")
    try:
        return rosbag.Bag(str(path), "r")
    except rosbag.ROSBagUnindexedException as e:
        raise ReplayError(
            f"{path}: the bag is not indexed (a recording cut short?): run 'rosbag reindex' on a "
            f"copy first ({e})"
        ) from e
    except (rosbag.ROSBagException, OSError, ValueError) as e:
        raise ReplayError(f"{path}: not a readable bag: {e}") from e


def summarize(bag: Any, path: Path, input_topics: list[str]) -> BagSummary:
    """One pass over the bag: topics, the tf tree, the inputs' frames, clock jumps, and each
    input's transform age (its stamp minus the newest /tf stamp recorded before it)."""
    info = bag.get_type_and_topic_info().topics
    topics = {t: (i.msg_type, int(i.message_count)) for t, i in info.items()}
    summary = BagSummary(path, bag.get_start_time(), bag.get_end_time(), topics)
    wanted = [t for t in input_topics if t in topics] + [t for t in TF_TOPICS if t in topics]
    last_child_stamp: dict[str, float] = {}
    newest_tf_s = -math.inf
    try:
        for topic, msg, _t in bag.read_messages(topics=wanted):
            if topic in TF_TOPICS:
                for tf in msg.transforms:
                    child, stamp = tf.child_frame_id.lstrip("/"), tf.header.stamp.to_sec()
                    summary.tf_parents[child] = tf.header.frame_id.lstrip("/")
                    if topic == "/tf":
                        before = last_child_stamp.get(child)
                        if before is not None and stamp < before - CLOCK_JUMP_S:
                            summary.clock_jumps.append(
                                f"/tf {child} goes back {before - stamp:.1f} s (from {before:.3f} "
                                f"to {stamp:.3f})"
                            )
                        last_child_stamp[child] = stamp
                        newest_tf_s = max(newest_tf_s, stamp)
            elif hasattr(msg, "header"):
                summary.frames.setdefault(topic, msg.header.frame_id.lstrip("/"))
                if math.isfinite(newest_tf_s):
                    stamp_s = msg.header.stamp.to_sec()
                    summary.transform_ages_s.setdefault(topic, []).append(stamp_s - newest_tf_s)
                    summary.input_stamps_s.setdefault(topic, []).append(stamp_s)
    except Exception as e:  # noqa: BLE001 - rosbag raises several types for damaged chunks
        raise ReplayError(f"{path}: reading the bag failed: {type(e).__name__}: {e}") from e
    return summary


def tf_root(frame: str, parents: dict[str, str]) -> tuple[str, list[str]]:
    chain = [frame]
    while chain[-1] in parents and len(chain) < 100:
        chain.append(parents[chain[-1]])
    return chain[-1], chain


def check(summary: BagSummary, pipeline: Pipeline) -> list[str]:
    """Why this bag cannot feed this pipeline; empty when it can."""
    problems = []
    listed = ", ".join(sorted(summary.topics)) or "none"
    has_tf = any(t in summary.topics for t in TF_TOPICS)
    if not has_tf:
        problems.append("the bag has no /tf or /tf_static: nothing places the sensors")
    for capability in pipeline.capabilities:
        data = [i for i in capability.inputs if i.frame_of_data]
        present = [i for i in capability.inputs if i.topic in summary.topics]
        if not any(i.frame_of_data for i in present):
            wanted = ", ".join(f"{i.topic} ({i.name})" for i in data)
            problems.append(
                f"none of the {capability.name}'s topics is in the bag (wanted {wanted}; the bag "
                f"has {listed})"
            )
        for i in present:
            kind = summary.topics[i.topic][0]
            if kind != i.msg_type:
                problems.append(
                    f"{i.topic} carries {kind}, but the {capability.name}'s {i.name} needs "
                    f"{i.msg_type}"
                )
        frames = [
            summary.frames[i.topic]
            for i in present
            if i.frame_of_data and i.topic in summary.frames
        ]
        if capability.name == "costmap":
            frames.insert(0, pipeline.robot_frame)
        if has_tf:
            problems += _unjoined(capability.frame, frames, summary.tf_parents)
    problems += [f"the clock jumps back: {j}" for j in summary.clock_jumps[:3]]
    return problems


def _unjoined(target: str, frames: list[str], parents: dict[str, str]) -> list[str]:
    root, _ = tf_root(target, parents)
    problems = []
    for frame in dict.fromkeys(frames):
        other_root, chain = tf_root(frame, parents)
        if other_root != root:
            problems.append(
                f"no tf joins '{frame}' to '{target}' (the bag's tf goes "
                f"{' <- '.join(reversed(chain))} and {target} reaches {root})"
            )
    return problems
