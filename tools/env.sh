# Sourced by the tools: the environment every build, test and demo runs in.
# Debian's python3 must come first (pyenv or a venv would hide rospy and catkin_pkg).
export PATH="/usr/bin:/bin:$PATH"
export ROS_HOSTNAME=localhost
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
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
