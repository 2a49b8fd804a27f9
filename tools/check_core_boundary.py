#!/usr/bin/env python3
"""The ROS-free core as a rule, not a habit (docs/development.md, "Layout").

Debian installs ROS headers in /usr/include next to everything else, so a ROS include in the core
would compile. This check fails instead:

  check_core_boundary.py sources          every #include in the core's sources and headers is the
                                          standard library, the core itself or an allowed
                                          third-party library (make lint)
  check_core_boundary.py built BUILD_DIR  the built core library needs no ROS library, and no
                                          header the compiler read for it belongs to a ROS
                                          package (make test, through test/pytest)
"""

from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterable
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
CORE_DIRS = ("src/core", "include/downstream_perception/core")
# Third-party libraries the core may use (DEVELOPERS: Eigen, OpenCV, PCL, OctoMap; plus the
# header-only robin-map and Boost.Math): the first path component of an angle-bracket include.
ALLOWED_ROOTS = {"Eigen", "unsupported", "octomap", "tsl", "boost", "opencv2", "pcl", "sys"}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
# Libraries of ROS packages (Debian's names): a core that links one of these is not ROS-free.
ROS_LIBRARY = re.compile(
    r"^lib(ros|roscpp|rosconsole|rostime|cpp_common|xmlrpcpp|tf2|nodelet|pluginlib|class_loader|"
    r"dynamic_reconfigure|diagnostic_updater|message_filters|laser_geometry|image_transport|"
    r"cv_bridge|pcl_ros|costmap_2d)"
)


def core_files(repo: Path = REPO) -> Iterable[Path]:
    for folder in CORE_DIRS:
        yield from sorted(p for p in (repo / folder).rglob("*") if p.suffix in (".h", ".cpp"))


def include_violation(quote: str, target: str) -> str | None:
    """Why this include does not belong in the core, or None."""
    if quote == '"':
        if target.startswith("downstream_perception/") and not target.startswith(
            "downstream_perception/core/"
        ):
            return "a header of the ROS glue (only downstream_perception/core/ is ROS-free)"
        return None
    root = target.split("/", 1)[0]
    if "/" not in target or root in ALLOWED_ROOTS:
        return None
    return f"'{root}/' is not an allowed core dependency ({', '.join(sorted(ALLOWED_ROOTS))})"


def check_sources(repo: Path = REPO) -> list[str]:
    problems = []
    for path in core_files(repo):
        for number, line in enumerate(path.read_text().splitlines(), 1):
            match = INCLUDE.match(line)
            if match and (why := include_violation(match.group(1), match.group(2))):
                problems.append(f"{path.relative_to(repo)}:{number}: {line.strip()}: {why}")
    return problems


def ros_package_include_dirs() -> set[str]:
    """The include folders of the installed ROS packages (/usr/include/<package>)."""
    try:
        names = subprocess.run(
            ["rospack", "list-names"], capture_output=True, text=True, check=True, timeout=60
        ).stdout.split()
    except (OSError, subprocess.SubprocessError):
        names = []
    # Packages whose headers are not ROS code (Debian packages them as ROS packages too).
    not_ros = {"eigen", "octomap", "boost", "downstream_perception"}
    return {f"/usr/include/{n}/" for n in names if n not in not_ros}


def check_built(build_dir: Path, library: Path) -> list[str]:
    problems = []
    dynamic = subprocess.run(
        ["readelf", "-d", str(library)], capture_output=True, text=True, check=True
    ).stdout
    for needed in re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", dynamic):
        if ROS_LIBRARY.match(needed):
            problems.append(f"{library.name} needs the ROS library {needed}")
    ros_dirs = ros_package_include_dirs()
    depfiles = list((build_dir / "CMakeFiles" / "downstream_perception_core.dir").rglob("*.d"))
    depfiles += (build_dir / "CMakeFiles" / "downstream_perception_core.dir").rglob("*.make")
    if not depfiles:
        problems.append(f"no dependency files of the core under {build_dir} (not built?)")
    for depfile in depfiles:
        for header in re.findall(r"(/usr/include/[^\s:\\]+)", depfile.read_text(errors="replace")):
            if any(header.startswith(d) for d in ros_dirs):
                problems.append(f"{depfile.name}: the core reads the ROS header {header}")
    return sorted(set(problems))


def main(argv: list[str]) -> int:
    if argv[:1] == ["sources"]:
        problems = check_sources()
    elif argv[:1] == ["built"] and len(argv) == 3:
        problems = check_built(Path(argv[1]), Path(argv[2]))
    else:
        print(__doc__)
        return 2
    for problem in problems:
        print(f"core boundary: {problem}", file=sys.stderr)
    print(f"core boundary: {'ok' if not problems else f'{len(problems)} problem(s)'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
