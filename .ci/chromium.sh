#!/usr/bin/env bash
# Headless Chromium and its WebDriver for the studio's browser test (tests/studio_page/): Debian's
# `chromium` and `chromium-driver` (/usr/bin/chromium, /usr/bin/chromedriver). The test starts
# chromedriver itself and gives Chromium the flags it needs on a closed network as root.
set -euo pipefail
if command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1; then
  chromium --version 2>/dev/null || true
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends chromium chromium-driver >/dev/null
chromium --version 2>/dev/null || true
chromedriver --version
