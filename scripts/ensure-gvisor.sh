#!/usr/bin/env bash
# Registers gVisor's runsc with the Docker engine for the tests that play robots under it
# (limits.robot_runtime, configs/README.md), on Debian/Ubuntu as root: installs Debian's runsc
# when missing, adds it to /etc/docker/daemon.json (keeping what the file has) and reloads the
# engine with SIGHUP, which leaves running containers alone. Anything it cannot do is said and
# skipped: the tests that need runsc then skip with the reason.
set -euo pipefail
if docker info --format '{{json .Runtimes}}' 2>/dev/null | grep -q '"runsc"'; then
  echo "==> gVisor runtime registered"
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null || [ -n "${DOCKER_HOST:-}" ]; then
  echo "==> gVisor runtime not registered (needs root, apt-get and the local engine); its tests skip"
  exit 0
fi
mkdir -p /var/log/hlvs
if ! command -v runsc >/dev/null; then
  echo "==> installing runsc (log: /var/log/hlvs/apt.log)"
  if ! apt-get install -y -qq --no-install-recommends runsc >>/var/log/hlvs/apt.log 2>&1; then
    echo "==> runsc could not be installed (see /var/log/hlvs/apt.log); its tests skip"
    exit 0
  fi
fi
pid=$(pidof dockerd || true)
if [ -z "$pid" ] || [ "$(wc -w <<<"$pid")" != 1 ]; then
  echo "==> no single local dockerd to reload; the gVisor tests skip"
  exit 0
fi
mkdir -p /etc/docker
python3 - /etc/docker/daemon.json "$(command -v runsc)" <<'PY'
import json, sys
from pathlib import Path
path, runsc = Path(sys.argv[1]), sys.argv[2]
data = json.loads(path.read_text()) if path.exists() and path.read_text().strip() else {}
# --network=host: gVisor uses the network namespace Docker made for the container
# (configs/README.md says why its own network stack cannot be used here).
data.setdefault("runtimes", {})["runsc"] = {"path": runsc, "runtimeArgs": ["--network=host"]}
path.write_text(json.dumps(data, indent=2) + "\n")
PY
echo "==> registering runsc in /etc/docker/daemon.json and reloading dockerd"
kill -HUP "$pid"
for _ in $(seq 1 40); do
  if docker info --format '{{json .Runtimes}}' 2>/dev/null | grep -q '"runsc"'; then
    echo "==> gVisor runtime registered"
    exit 0
  fi
  sleep 0.5
done
echo "==> dockerd did not list runsc after the reload (see /var/log/hlvs/dockerd.log); its tests skip"
