# Sourced by the tools: the environment every build, test and demo runs in.
# Debian's python3 must come first (pyenv or a venv would hide rospy and catkin_pkg).
export PATH="/usr/bin:/bin:$PATH"
export ROS_HOSTNAME=localhost
REPO="$(cd -P "$(dirname "${BASH_SOURCE[0]}")" && cd .. && pwd)"  # -P: the repository, also when reached through the workspace's links
WS="$REPO/.ws"
export ROS_HOME="$WS/ros_home"
export REPO WS
source_workspace() {
  # setup.bash reads unset variables: source it with nounset off (see the Debian notes, P7).
  local had_u=0
  [[ $- == *u* ]] && had_u=1 && set +u
  # shellcheck disable=SC1091
  source "$WS/devel/setup.bash"
  ((had_u)) && set -u
  return 0
}
system_venv() {
  # A venv at $1 on top of Debian's python3 and its packages (--system-site-packages: rospy,
  # numpy and the built workspace's packages stay Debian's). Idempotent.
  if [[ ! -x "$1/bin/python" ]]; then
    mkdir -p "$(dirname "$1")"
    /usr/bin/python3 -m venv --system-site-packages "$1"
  fi
}
link_package() {
  # The package as the workspace's source ($1/src/downstream_perception): a directory of links to
  # the repository's entries, not one link to the repository, so that it does not contain the
  # workspaces themselves (.ws*). rosrun searches the package directory recursively: through a
  # link to the repository it found every script again in .ws/devel, .ws/build and the loop
  # .ws/src/downstream_perception/.ws/... and refused to choose.
  local dest="$1/src/downstream_perception" entry name
  [[ -L "$dest" ]] && rm -f "$dest"
  mkdir -p "$dest"
  find "$dest" -mindepth 1 -maxdepth 1 \( -type l -o -type f \) -delete  # f: copies of old
  for entry in "$REPO"/* "$REPO"/.[!.]*; do
    name="$(basename "$entry")"
    [[ -e "$entry" ]] || continue
    case "$name" in .ws* | .git | .ruff_cache | out) continue ;; esac
    ln -sfn "$entry" "$dest/$name"
  done
}
pybind11_cmake_args() {
  # -Dpybind11_DIR=<PyPI pybind11's CMake dir> when tools/python_venv.sh installed it (numpy 1
  # and 2); nothing (Debian's pybind11 2.10, numpy 1 only) when it could not.
  local dir
  if dir="$("$WS/build-venv/bin/python" -m pybind11 --cmakedir 2> /dev/null)"; then
    echo "-Dpybind11_DIR=$dir"
  fi
}
