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
build_instrumented() {
  # build_instrumented WS FLAGS LABEL [cmake args and targets...]: builds the given targets of the
  # package with sanitizer FLAGS in a catkin workspace of its own (WS: .ws keeps its Release
  # build), RelWithDebInfo at -O1 for readable reports, no LTO; log in WS/build.log. On failure
  # prints the errors and "LABEL: 0 passed, 1 failed (build failed ...)" and returns 1.
  local ws="$1" flags="$2" label="$3" start=$SECONDS
  shift 3
  mkdir -p "$ws/src" "$ROS_HOME"
  link_package "$ws"
  if [[ -f "$ws/build/CMakeCache.txt" ]] &&
    ! grep -q "PYTHON_EXECUTABLE:FILEPATH=/usr/bin/python3" "$ws/build/CMakeCache.txt"; then
    rm -rf "$ws/build" "$ws/devel" # a cache configured with another python (pitfall P14)
  fi
  if ! (cd "$ws" && catkin_make -j2 -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCATKIN_ENABLE_TESTING=ON \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF \
    "-DCMAKE_CXX_FLAGS=$flags" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" \
    "-DCMAKE_EXE_LINKER_FLAGS=$flags" "-DCMAKE_SHARED_LINKER_FLAGS=$flags" \
    "-DCMAKE_MODULE_LINKER_FLAGS=$flags" "$@" > "$ws/build.log" 2>&1); then
    grep -E 'error|Error' "$ws/build.log" | head -40 || true
    tail -40 "$ws/build.log"
    echo "$label: 0 passed, 1 failed (build failed; log: $ws/build.log)"
    return 1
  fi
  echo "$label: build ok in $((SECONDS - start)) s (log: $ws/build.log)"
}
