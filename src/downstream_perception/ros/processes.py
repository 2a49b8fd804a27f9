"""ROS processes started by the demo, the benchmarks and the soaks (roscore, roslaunch): a free
master port and a clean stop. Needs no rospy, so the scripts can start before ROS is sourced."""

from __future__ import annotations

import signal
import socket
import subprocess


def free_port() -> int:
    """A TCP port on loopback that nothing listens on now (for a private ROS master)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def stop_process(proc: subprocess.Popen[bytes], timeout_s: float = 20.0) -> None:
    """SIGINT (roslaunch's clean shutdown), then SIGKILL after `timeout_s`."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            proc.kill()
