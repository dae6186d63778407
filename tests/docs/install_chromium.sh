#!/usr/bin/env bash
# Install Debian's chromium for the browser tests (tests/docs, tests/explore) when
# /usr/bin/chromium is missing. Needs root (apt-get); .ci/run calls it before the tests.
set -euo pipefail
log() { printf '[install-chromium %s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }

if [ -x /usr/bin/chromium ]; then
    log "chromium present: $(/usr/bin/chromium --version 2>/dev/null || echo '?')"
    exit 0
fi
[ "$(id -u)" = 0 ] || { log "ERROR: needs root to apt-get install chromium"; exit 1; }
T0=$(date +%s)
export DEBIAN_FRONTEND=noninteractive
apt_log="${TMPDIR:-/tmp}/safebasins-chromium-apt.log"
# (wait up to 2 min for a dpkg lock held by another apt run; retry a failed download once)
for attempt in 1 2; do
    if timeout 600 apt-get -o DPkg::Lock::Timeout=120 update -qq >"$apt_log" 2>&1 \
        && timeout 600 apt-get -o DPkg::Lock::Timeout=120 install -y -qq --no-install-recommends \
            chromium >>"$apt_log" 2>&1; then
        break
    fi
    if [ "$attempt" = 2 ]; then
        cat "$apt_log" >&2; log "ERROR: apt-get install chromium failed"; exit 1
    fi
    log "apt-get failed, retrying in 10 s"; sleep 10
done
log "installed $(/usr/bin/chromium --version 2>/dev/null || echo chromium) in $(($(date +%s) - T0)) s"
