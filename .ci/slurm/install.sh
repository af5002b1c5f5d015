#!/usr/bin/env bash
# Install a single-node SLURM from Debian packages (run as root): controller, node daemon, accounting daemon,
# MariaDB for the accounting database (sacct needs slurmdbd; 22.05 has no file-based accounting storage) and munge.
# Idempotent: does nothing when everything is installed already.
set -euo pipefail

PACKAGES=(slurm-wlm slurm-client slurmdbd munge mariadb-server)

missing=()
for pkg in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "slurm: packages already installed"
    exit 0
fi
echo "slurm: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
