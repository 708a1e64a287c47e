#!/usr/bin/env bash
# Install everything deckbridge needs on a fresh Debian machine (idempotent),
# then run the given command inside the project's virtual environment.
#   bash scripts/bootstrap.sh deckbridge run -o jar-report
#   bash scripts/bootstrap.sh pytest
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$root/.venv"
stamp="$venv/.deckbridge-installed"

need_apt=()
command -v ccx >/dev/null 2>&1 || need_apt+=(calculix-ccx)
[ -e /usr/include/suitesparse/cholmod.h ] || need_apt+=(libsuitesparse-dev)
dpkg -s libopenblas0-pthread >/dev/null 2>&1 || need_apt+=(libopenblas0-pthread)
command -v chromium >/dev/null 2>&1 || need_apt+=(chromium)
# the gmsh wheel (test extra: an independent mesh generator for the import tests) links these X/GL libraries
ldconfig -p 2>/dev/null | grep -q 'libGLU\.so\.1' || need_apt+=(libglu1-mesa libxcursor1 libxft2 libxinerama1)
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "bootstrap: apt-get install ${need_apt[*]}" >&2
  sudo_=""; [ "$(id -u)" -eq 0 ] || sudo_="sudo"
  $sudo_ apt-get update -qq >/dev/null
  DEBIAN_FRONTEND=noninteractive $sudo_ apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

find_python() {
  for cand in python3.12 "$(pyenv root 2>/dev/null)/versions/3.12"*/bin/python3.12 /usr/bin/python3.12; do
    if [ -n "$cand" ] && "$cand" -c 'import sys; assert sys.version_info[:2] >= (3, 12)' 2>/dev/null; then
      echo "$cand"; return 0
    fi
  done
  for cand in "$(pyenv root 2>/dev/null)/versions/3.1"[3-9]*/bin/python3; do
    if "$cand" -c 'import sys; assert sys.version_info[:2] >= (3, 12)' 2>/dev/null; then echo "$cand"; return 0; fi
  done
  return 1
}

if [ ! -x "$venv/bin/python" ]; then
  py="$(find_python)" || { echo "bootstrap: Python >= 3.12 not found" >&2; exit 1; }
  "$py" -m venv "$venv"
fi
hash_now="$(cat "$root/pyproject.toml" | sha256sum | cut -c1-16)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$hash_now" ]; then
  echo "bootstrap: installing Python packages into $venv" >&2
  log="$venv/pip-install.log"
  if ! { "$venv/bin/python" -m pip install -q --upgrade pip \
         && "$venv/bin/python" -m pip install -q -e "$root[fast,test,docs]"; } >"$log" 2>&1; then
    tail -n 40 "$log" >&2
    echo "bootstrap: pip install failed (full log: $log)" >&2
    exit 1
  fi
  echo "$hash_now" > "$stamp"
fi
[ $# -gt 0 ] || exit 0
export PATH="$venv/bin:$PATH"
cd "$root"
exec "$@"
