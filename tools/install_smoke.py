"""Smoke test of an install space (run by tools/install_check.sh with only install/setup.bash
sourced). Every check prints one line; the exit status is the number of failed checks."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

INSTALL = Path(sys.argv[1]).resolve()
REPO = Path(sys.argv[2]).resolve()
PACKAGE = "downstream_perception"
failures = 0


def check(name: str, test: Callable[[], str]) -> None:
    global failures
    try:
        detail = test()
        print(f"install-check: ok   {name}: {detail}")
    except Exception as e:  # noqa: BLE001 - every failure is reported, then counted
        failures += 1
        print(f"install-check: FAIL {name}: {e}")


def inside_install(path: str) -> str:
    resolved = Path(path).resolve()
    if INSTALL not in resolved.parents:
        raise AssertionError(f"{resolved} is not inside the install space {INSTALL}")
    return str(resolved.relative_to(INSTALL))


def python_package() -> str:
    import downstream_perception
    import downstream_perception._core as core
    import downstream_perception.ros.util  # noqa: F401
    import downstream_perception.sim  # noqa: F401

    for module in (downstream_perception, core):
        inside_install(module.__file__)
    grid = downstream_perception.GridGeometry(100, 100, 0.25, 0.0, 0.0)
    assert grid.world_to_cell(5.2, 5.0) == (20, 20)  # the core computes
    return inside_install(core.__file__)


def messages() -> str:
    from downstream_perception.msg import DetectedObjectArray, TrackedObjectArray
    from downstream_perception.srv import SaveMap, TransformPose  # noqa: F401

    TrackedObjectArray()
    return inside_install(sys.modules[DetectedObjectArray.__module__].__file__)


def rospack(*args: str) -> str:
    return subprocess.run(
        ["rospack", *args], capture_output=True, text=True, check=True, timeout=60
    ).stdout


def package_found() -> str:
    return inside_install(rospack("find", PACKAGE).strip())


def plugins(base: str, xml_name: str) -> Callable[[], str]:
    def test() -> str:
        listed = [line.split() for line in rospack("plugins", "--attrib=plugin", base).splitlines()]
        paths = [p for pkg, p in listed if pkg == PACKAGE]
        assert paths, f"rospack lists no {base} plugins of {PACKAGE}"
        xml = Path(paths[0])
        assert xml.name == xml_name, xml
        inside_install(str(xml))
        libraries = re.findall(r'<library path="([^"]+)"', xml.read_text())
        assert libraries, f"{xml} names no library"
        for library in libraries:
            so = INSTALL / f"{library}.so"
            assert so.is_file(), f"{xml.name} names {library}, but {so} is missing"
        classes = len(re.findall(r"<class ", xml.read_text()))
        return f"{classes} classes in {len(libraries)} libraries"

    return test


def launch_costmap() -> str:
    from downstream_perception.ros.processes import free_port  # the installed one

    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}")
    launch = subprocess.Popen(
        ["roslaunch", "-p", str(port), PACKAGE, "costmap.launch", "bond:=false"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline:
            out = subprocess.run(
                ["rostopic", "echo", "-n", "1", "/costmap/costmap/info"],
                env=env,
                capture_output=True,
                text=True,
                timeout=90,
                check=False,
            ).stdout
            if "width" in out:
                width = re.search(r"width: (\d+)", out)
                assert width and int(width.group(1)) == 200, out
                return "costmap.launch published a 200 x 200 grid on /costmap/costmap"
            time.sleep(1.0)
        raise AssertionError("no grid on /costmap/costmap within 60 s")
    finally:
        launch.send_signal(2)
        try:
            out, _ = launch.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            launch.kill()
            out, _ = launch.communicate()
        if failures:
            print(out[-3000:])


def no_links_out() -> str:
    links = [p for p in INSTALL.rglob("*") if p.is_symlink()]
    outside = [p for p in links if INSTALL not in p.resolve().parents]
    assert not outside, f"links out of the install space: {[str(p) for p in outside[:5]]}"
    return f"{sum(1 for _ in INSTALL.rglob('*'))} entries, none a link out of it"


def nothing_from_the_source_tree() -> str:
    for entry in sys.path + os.environ.get("ROS_PACKAGE_PATH", "").split(":"):
        path = Path(entry).resolve() if entry else None
        if path is None or path == INSTALL or INSTALL in path.parents:
            continue
        if path == REPO or REPO in path.parents:
            raise AssertionError(f"{entry} (the repository) is on a search path")
    return "no search path reaches the repository"


check("self-contained", no_links_out)
check("search paths", nothing_from_the_source_tree)
check("python package and compiled core", python_package)
check("messages and services", messages)
check("rospack find", package_found)
check("nodelet plugins", plugins("nodelet", "nodelet_plugins.xml"))
check("layer plugins", plugins(PACKAGE, "layer_plugins.xml"))
check("launch", launch_costmap)
print(f"install-check: {8 - failures} passed, {failures} failed")
sys.exit(failures)
