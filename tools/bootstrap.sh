#!/usr/bin/env bash
# Installs the Debian 12 packages this project needs, only those missing. Idempotent: a second
# run installs nothing and makes no network access. Run as root (or with sudo available).
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

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

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
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "[bootstrap] done"
