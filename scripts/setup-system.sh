#!/usr/bin/env bash
# Installs the host packages the runner and its tests use, when missing, on Debian/Ubuntu as root.
set -euo pipefail
need=()
have() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "ok installed"; }
for pkg in docker.io docker-compose docker-registry apache2-utils mmdebstrap libosmesa6 ffmpeg openssh-server iproute2 postgresql chromium gcc libc6-dev; do
  have "$pkg" || need+=("$pkg")
done
if [ ${#need[@]} -eq 0 ]; then
  echo "==> host packages present"
  exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then
  echo "hlvs setup: missing host packages: ${need[*]}" >&2
  echo "hlvs setup: install them with your package manager (Debian/Ubuntu: apt-get install ${need[*]})," >&2
  echo "hlvs setup: or run as root on Debian/Ubuntu so that 'make' installs them." >&2
  exit 1
fi
echo "==> installing host packages: ${need[*]} (log: /var/log/hlvs/apt.log)"
mkdir -p /var/log/hlvs
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq >>/var/log/hlvs/apt.log 2>&1
# --force-unsafe-io: dpkg skips its fsync per file (minutes on a slow disk); after a power loss
# during the install, reinstall the packages.
apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${need[@]}" \
  >>/var/log/hlvs/apt.log 2>&1 || {
  echo "hlvs setup: apt-get install failed; see /var/log/hlvs/apt.log" >&2; exit 1; }
# The Debian registry and sshd packages start services we do not use; tests start their own.
systemctl disable --now docker-registry ssh >/dev/null 2>&1 || true
