#!/usr/bin/env bash
# Installs the packages this project needs, only those missing. Idempotent: a second run installs
# nothing and makes no network access. Run as root (or with sudo available).
#
# The distribution comes from /etc/os-release (issue 45, item 5):
#   Debian 12 (bookworm): what CI builds and tests on.
#   Ubuntu 24.04 (noble): every package under the same name (the DDS, OctoMap, CLI11, benchmark
#     and JSON ones looked up on packages.ubuntu.com; most are in universe), in other versions
#     (Fast DDS 2.11 instead of 2.9, Cyclone DDS 0.10.4, GCC 13): not tested. A package apt cannot
#     find stops the script, by name, before anything is installed.
#   Anything else: the list of Debian 12 packages it needs, and exit 1. Install their equivalents
#     yourself, then run tools/test.sh or tools/demo.sh with VNSBA_BOOTSTRAP=skip.
# docs/platforms.md says what is known of each.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libyaml-cpp-dev liboctomap-dev octomap-tools
  libfastrtps-dev libfastcdr-dev fastddsgen default-jre-headless
  libcli11-dev libspdlog-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libtinyxml2-dev librsvg2-bin
  librsvg2-dev libcairo2-dev
  openssl libssl-dev
  cyclonedds-dev cyclonedds-tools fastdds-tools
)

if [ "${VNSBA_BOOTSTRAP:-}" = skip ]; then
  echo "[bootstrap] skipped (VNSBA_BOOTSTRAP=skip): the ${#packages[@]} packages are up to you"
  exit 0
fi

os_id="" os_version="" os_name="an unknown distribution (no /etc/os-release)"
if [ -r /etc/os-release ]; then
  # shellcheck disable=SC1091  # the system's file
  os_id=$(. /etc/os-release && echo "${ID:-}")
  # shellcheck disable=SC1091
  os_version=$(. /etc/os-release && echo "${VERSION_ID:-}")
  # shellcheck disable=SC1091
  os_name=$(. /etc/os-release && echo "${PRETTY_NAME:-$os_id $os_version}")
fi

# What is missing, by Debian's names, wherever dpkg answers (Debian and its derivatives).
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

case "$os_id:$os_version" in
  debian:12) ;;
  ubuntu:24.04)
    # Every package has the same name as on Debian 12. Not tested there: say so once.
    echo "[bootstrap] $os_name: Ubuntu 24.04's packages under Debian 12's names; this platform" \
      "is not tested (docs/platforms.md)"
    ;;
  *)
    # Another system with every package installed (a Debian derivative, a newer Debian): go on,
    # untested; otherwise say what it needs.
    if [ ${#missing[@]} -eq 0 ]; then
      echo "[bootstrap] $os_name: every package present; this platform is not tested" \
        "(docs/platforms.md)"
      exit 0
    fi
    {
      echo "[bootstrap] $os_name is not supported: this script installs the packages of"
      echo "[bootstrap] Debian 12 (and Ubuntu 24.04). The build needs, by Debian 12's names:"
      printf '%s\n' "${packages[@]}" | paste -sd' ' | fold -s -w 90 |
        sed 's/ *$//; s/^/[bootstrap]   /'
      echo "[bootstrap] Install their equivalents (Fast DDS 2.x with fastddsgen, Cyclone DDS 0.10"
      echo "[bootstrap] for the interop tests), then run tools/test.sh or tools/demo.sh with"
      echo "[bootstrap] VNSBA_BOOTSTRAP=skip. See docs/platforms.md."
    } >&2
    exit 1
    ;;
esac

if [ ${#missing[@]} -eq 0 ]; then
  echo "[bootstrap] all ${#packages[@]} packages present"
  exit 0
fi

echo "[bootstrap] installing: ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "[bootstrap] need root or sudo to install packages" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q

# A package the configured sources do not have stops here, by name, rather than in apt-get's
# error halfway through.
unavailable=()
for p in "${missing[@]}"; do
  candidate=$(apt-cache policy "$p" 2>/dev/null | sed -n 's/^ *Candidate: *//p')
  if [ -z "$candidate" ] || [ "$candidate" = "(none)" ]; then
    unavailable+=("$p")
  fi
done
if [ ${#unavailable[@]} -gt 0 ]; then
  {
    echo "[bootstrap] not available from this machine's apt sources: ${unavailable[*]}"
    if [ "$os_id" = ubuntu ]; then
      echo "[bootstrap] On Ubuntu most of them are in the universe component:" \
        "sudo add-apt-repository universe, then run this script again."
    fi
    echo "[bootstrap] Nothing was installed. docs/platforms.md says what the build needs them for."
  } >&2
  exit 1
fi

"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "[bootstrap] done"
