#!/usr/bin/env bash
# Installs the Debian packages listed in the given files (one per line, # comments) if any is
# missing. As root it runs apt-get; otherwise it prints the command to run and fails.
set -euo pipefail
packages=$(cat "$@" | sed -e 's/#.*//' | tr -s ' \n' '\n' | grep -v '^$' | sort -u)
missing=()
for package in $packages; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
  echo "missing Debian packages: ${missing[*]}" >&2
  echo "install them with: sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi
echo "installing Debian packages: ${missing[*]}"
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
