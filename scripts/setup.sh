#!/usr/bin/env bash
# Set up cpgbiped on a Debian machine with Python 3.11: the system packages MuJoCo's
# off-screen rendering, video writing and the rerun web-viewer check need (OSMesa, ffmpeg,
# chromium; apt, as root), then the package with its pinned dependencies (pip, editable).
# Safe to run again: it installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
need=()
ldconfig -p 2>/dev/null | grep -q 'libOSMesa\.so' || need+=(libosmesa6)
command -v ffmpeg >/dev/null 2>&1 || need+=(ffmpeg)
# Debian's chromium: the rerun web-viewer check (scripts/check_rerun_viewer.py, its test)
[[ -x /usr/bin/chromium ]] || need+=(chromium)
if ((${#need[@]})); then
  if [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null 2>&1; then
    echo "setup: apt-get install ${need[*]}"
    apt-get update -qq >/dev/null
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
  else
    echo "setup: warning: missing ${need[*]}; install them with: sudo apt-get install ${need[*]}" >&2
  fi
fi
python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore -e ".[test]"
command -v pyenv >/dev/null 2>&1 && pyenv rehash || true
echo "setup: ok ($(python3 -c 'import mujoco, dm_control, pymoo; print("mujoco", mujoco.__version__, "pymoo", pymoo.__version__)'))"
