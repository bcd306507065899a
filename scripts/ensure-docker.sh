#!/usr/bin/env bash
# Makes sure a Docker engine answers: uses the one running, starts the installed one, or says how to get one.
set -euo pipefail
if docker info >/dev/null 2>&1; then
  exit 0
fi
if [ -n "${DOCKER_HOST:-}" ]; then
  echo "hlvs setup: DOCKER_HOST=$DOCKER_HOST does not answer; start that engine or unset DOCKER_HOST" >&2
  exit 1
fi
if [ "$(id -u)" = 0 ] && command -v dockerd >/dev/null; then
  mkdir -p /var/log/hlvs
  echo "==> starting dockerd (log: /var/log/hlvs/dockerd.log)"
  # its own session: the engine outlives the shell (and its process group) that started it
  setsid nohup dockerd >>/var/log/hlvs/dockerd.log 2>&1 </dev/null &
  for _ in $(seq 1 60); do
    docker info >/dev/null 2>&1 && { echo "==> Docker engine ready"; exit 0; }
    sleep 0.5
  done
  echo "hlvs setup: dockerd did not answer within 30 s; see /var/log/hlvs/dockerd.log" >&2
  exit 1
fi
echo "hlvs setup: no Docker engine answers. Install Docker (Debian/Ubuntu: apt-get install docker.io)" >&2
echo "hlvs setup: and start it (systemctl start docker), or set DOCKER_HOST to a remote engine." >&2
exit 1
