# Shared by demo.sh, test.sh and the benchmarks: installs the Debian packages the package
# needs, lays out a catkin workspace inside the repository (.ws, git-ignored) and builds it.
# Source it; it defines REPO (this package's folder), ROOT (the repository, which holds the three
# packages), WS and the functions below.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ROOT="$(dirname "$REPO")"
WS="${VF_WS:-$ROOT/.ws}"
# Debian's ROS lives in /usr; a pyenv python3 earlier on PATH has no ROS modules.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="${ROS_HOME:-$HOME/.ros}"
# Local runs: name this host by loopback, whatever its hostname resolves to.
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
# Nothing but apt installs and ~/.ros is written outside the repository.
export MPLCONFIGDIR="$WS/matplotlib"
export PYTHONDONTWRITEBYTECODE=1

# The repository's packages: the folders of ROOT that hold a package.xml.
vf_packages() {
  local xml
  for xml in "$ROOT"/*/package.xml; do basename "$(dirname "$xml")"; done
}

# The Debian packages: every dependency key of the packages' package.xml files, through the one
# mapping in scripts/debian_packages.txt (no rosdep database is needed); a key that names one of
# the repository's own packages is built, not installed. Plain bash and sed: on a fresh machine
# nothing else may be installed yet.
vf_apt_packages() {
  local key line found ours
  ours=" $(vf_packages | tr '\n' ' ') "
  for key in $(sed -nE 's#^ *<(buildtool_|build_|build_export_|exec_|test_)?depend>([^<]+)</.*#\2#p' \
                 "$ROOT"/*/package.xml | sort -u); do
    case "$ours" in *" $key "*) continue ;; esac
    found=""
    while read -r line; do
      case "$line" in "$key: "*) found="${line#"$key: "}" ;; esac
    done <"$REPO/scripts/debian_packages.txt"
    if [ -z "$found" ]; then
      echo "package.xml: dependency '$key' has no line in scripts/debian_packages.txt" >&2
      return 1
    fi
    echo "$found" | tr ' ' '\n'
  done | sort -u
}

vf_install_dependencies() {
  local missing=() packages=()
  local p
  mapfile -t packages < <(vf_apt_packages) && [ ${#packages[@]} -gt 0 ] || return 1
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "installing ${#missing[@]} Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

vf_build() {
  # The workspace's src/ holds one link per package of the repository. The workspace lies
  # beside the packages, in none of them, so rosrun's `find -L` never meets it. (A workspace of
  # the one-package layout held a folder of links instead: it is replaced.)
  local name
  mkdir -p "$WS/src"
  for name in $(vf_packages); do
    if [ -d "$WS/src/$name" ] && [ ! -L "$WS/src/$name" ]; then
      find "$WS/src/$name" -maxdepth 1 -type l -delete
      rmdir "$WS/src/$name"
    fi
    ln -sfn "$ROOT/$name" "$WS/src/$name"
  done
  local jobs launcher=()
  jobs="$(nproc 2>/dev/null || echo 2)"
  # Where ccache is installed (a developer's machine, not CI's), builds of several checkouts
  # share one cache: paths below the checkouts' parent are hashed relative.
  if command -v ccache >/dev/null 2>&1; then
    export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$ROOT")}"
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  (cd "$WS" && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 \
      -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" -j"$jobs" >"$WS/build.log" 2>&1) || {
    tail -n 60 "$WS/build.log"
    echo "build failed; full log: $WS/build.log" >&2
    return 1
  }
}

# Makes the built package visible to rosrun, roslaunch and rostest.
vf_source() {
  set +u
  # shellcheck disable=SC1091
  source "$WS/devel/setup.bash"
  set -u
}

# A TCP port in [base, base + count) that nothing on this host listens on, for a ROS master of
# our own; the search starts at a place that depends on the calling process.
vf_free_port() {
  local base="$1" count="$2" offset=$(( $$ % $2 )) k p
  for k in $(seq 0 $(( count - 1 ))); do
    p=$(( base + (offset + k) % count ))
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then
      echo "$p"
      return 0
    fi
  done
  echo "no free port in $base-$(( base + count - 1 ))" >&2
  return 1
}

# The median of the numbers among the arguments (the lower middle one of an even count); words
# such as "failed" or "n/a" are left out. Prints nothing if there is no number.
vf_median() {
  printf '%s\n' "$@" | { grep -E '^[0-9]+(\.[0-9]+)?$' || true; } | sort -g |
    awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)] }'
}
