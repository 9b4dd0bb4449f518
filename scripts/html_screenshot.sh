#!/usr/bin/env bash
# Screenshots an HTML file (e.g. a `bisect_html` report) with headless Chromium, to check a page's
# layout by eye. Installs Chromium with apt-get first if it is missing (needs root or sudo).
#
# Usage: scripts/html_screenshot.sh REPORT.html OUT.png [WIDTHxHEIGHT]   (default 1400x1800)
set -euo pipefail

usage() {
  echo "usage: $0 REPORT.html OUT.png [WIDTHxHEIGHT]   (default size 1400x1800)" >&2
  exit 2
}

if [ $# -lt 2 ] || [ $# -gt 3 ]; then usage; fi
html=$1
png=$2
size=${3:-1400x1800}
[ -f "$html" ] || { echo "$0: no such file: $html" >&2; usage; }
[[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "$0: size must be WIDTHxHEIGHT, got '$size'" >&2; usage; }
width=${BASH_REMATCH[1]}
height=${BASH_REMATCH[2]}
[ -d "$(dirname -- "$png")" ] || { echo "$0: no directory for $png" >&2; exit 2; }

browser=""
for candidate in chromium chromium-browser google-chrome; do
  if command -v "$candidate" >/dev/null 2>&1; then
    browser=$candidate
    break
  fi
done
if [ -z "$browser" ]; then
  echo "$0: installing chromium (apt-get)" >&2
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get update -q >/dev/null
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null
  browser=chromium
fi

# Chromium wants absolute file URLs and paths; it may print harmless GPU/DBus noise to stderr.
abs_html=$(cd "$(dirname -- "$html")" && pwd)/$(basename -- "$html")
abs_png=$(cd "$(dirname -- "$png")" && pwd)/$(basename -- "$png")
rm -f -- "$abs_png"
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
  --window-size="$width,$height" --screenshot="$abs_png" "file://$abs_html" 2>/dev/null || true
if [ ! -s "$abs_png" ]; then
  echo "$0: $browser wrote no screenshot to $abs_png" >&2
  exit 1
fi
echo "$abs_png"
