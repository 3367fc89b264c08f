#!/usr/bin/env bash
# The generated-client contract check (`make client-e2e`): generate a Python
# client from openapi.yaml with openapi-python-client into a temporary
# directory, install it, start the real binary on a temporary database and a
# free port with one job worker, and run tests/python/client_e2e.py against
# it. Fails on any generator warning that drops a route or schema.
#
#   SEATRIAL_BIN=target/release/seatrial bash tests/python/client_e2e.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=${SEATRIAL_BIN:-target/release/seatrial}
[ -x "$BIN" ] || { echo "no binary at $BIN (cargo build --release --bin seatrial)"; exit 1; }

tmp=$(mktemp -d)
server=""
cleanup() {
  if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; wait "$server" 2>/dev/null || true; fi
  rm -rf "$tmp"
}
trap cleanup EXIT

openapi-python-client generate --path openapi.yaml --meta setup --output-path "$tmp/client" >"$tmp/generate.log" 2>&1 \
  || { cat "$tmp/generate.log"; echo "openapi-python-client failed"; exit 1; }
# A schema or response it cannot parse is left out of the client with a warning.
if grep -qE "^(WARNING|Unable to)|will be omitted|has resulted in the removal" "$tmp/generate.log"; then
  cat "$tmp/generate.log"; echo "openapi-python-client dropped part of the spec"; exit 1
fi
python3 -m pip install -q --disable-pip-version-check --no-deps --force-reinstall "$tmp/client" >/dev/null 2>&1 \
  || python3 -m pip install -q --disable-pip-version-check --no-deps --force-reinstall --break-system-packages "$tmp/client" >/dev/null

touch "$tmp/server.log"
"$BIN" --db "$tmp/seatrial.db" --listen 127.0.0.1:0 --job-workers 1 --web-dir web >"$tmp/server.log" 2>&1 &
server=$!
base=""
for _ in $(seq 1 300); do
  base=$(sed -n 's/^seatrial listening on \(http:\/\/[^ ]*\)$/\1/p' "$tmp/server.log" | head -n1)
  [ -n "$base" ] && break
  kill -0 "$server" 2>/dev/null || { cat "$tmp/server.log"; echo "the server exited"; exit 1; }
  sleep 0.1
done
[ -n "$base" ] || { cat "$tmp/server.log"; echo "the server did not start in 30 s"; exit 1; }
echo "generated client against $base"
python3 tests/python/client_e2e.py "$base" || { echo "--- server log"; tail -n 50 "$tmp/server.log"; exit 1; }
