# The two commands a newcomer needs (see README):
#   make run   – start the service with the demo campaigns on http://127.0.0.1:8080
#   make test  – install what the tests need, then run every test
# Everything builds and tests in release: debug builds run the numerics far slower.

SHELL := /bin/bash
.DEFAULT_GOAL := run
DB ?= data/seatrial.db
LISTEN ?= 127.0.0.1:8080

.PHONY: fuzz fuzz-merge load-test schemathesis run test deps web-deps browser octave spec-validator py-deps client-deps test-rust test-spec test-web client-e2e fmt lint

run: web-deps
	cargo run --release --bin seatrial -- --demo --db $(DB) --listen $(LISTEN) --web-dir web

web-deps:
	@command -v npm >/dev/null || { echo "npm is needed for the web UI's uPlot (apt-get install -y nodejs npm)"; exit 1; }
	@if [ ! -d web/node_modules/uplot ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then npm ci --prefix web --no-audit --no-fund; fi

# Debian's Chromium for the headless browser tests (playwright-core drives it; no browser download).
browser:
	@if ! command -v chromium >/dev/null && [ ! -x /usr/bin/chromium ]; then \
	  echo "installing Debian chromium for the browser tests"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq chromium >/dev/null; \
	fi

# Debian's Octave runs the .m export in tests/python/check_exports.py (discretizes and simulates
# the step response itself); without it that check is skipped. apt-get update only when the
# plain install fails (a stale or empty package list).
octave:
	@if ! command -v octave >/dev/null && ! command -v octave-cli >/dev/null; then \
	  echo "installing Debian octave for the export checks"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends octave >/dev/null \
	  || { $$SUDO apt-get update -qq && $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends octave >/dev/null; }; \
	fi

# openapi-spec-validator (PyPI, pinned) checks openapi.yaml against the OpenAPI 3.1 schema.
OPENAPI_SPEC_VALIDATOR := 0.9.0
spec-validator:
	@command -v python3 >/dev/null || { echo "python3 is needed to validate openapi.yaml (apt-get install -y python3 python3-pip)"; exit 1; }
	@python3 -c "import importlib.metadata as m; assert m.version('openapi-spec-validator') == '$(OPENAPI_SPEC_VALIDATOR)'" 2>/dev/null \
	  || python3 -m pip install -q --disable-pip-version-check openapi-spec-validator==$(OPENAPI_SPEC_VALIDATOR) \
	  || python3 -m pip install -q --disable-pip-version-check --break-system-packages openapi-spec-validator==$(OPENAPI_SPEC_VALIDATOR)

# numpy and scipy (PyPI, pinned) for tests/python/check_exports.py, which
# tests/api_exports.rs runs on the .npz / state-space exports.
NUMPY := 2.3.5
SCIPY := 1.16.3
py-deps:
	@command -v python3 >/dev/null || { echo "python3 is needed for the export checks (apt-get install -y python3 python3-pip)"; exit 1; }
	@python3 -c "import importlib.metadata as m; assert m.version('numpy') == '$(NUMPY)' and m.version('scipy') == '$(SCIPY)'" 2>/dev/null \
	  || python3 -m pip install -q --disable-pip-version-check numpy==$(NUMPY) scipy==$(SCIPY) \
	  || python3 -m pip install -q --disable-pip-version-check --break-system-packages numpy==$(NUMPY) scipy==$(SCIPY)

# openapi-python-client (PyPI, pinned) generates the Python client of the contract check.
OPENAPI_PYTHON_CLIENT := 0.29.1
client-deps: py-deps
	@python3 -c "import importlib.metadata as m; assert m.version('openapi-python-client') == '$(OPENAPI_PYTHON_CLIENT)'" 2>/dev/null \
	  || python3 -m pip install -q --disable-pip-version-check openapi-python-client==$(OPENAPI_PYTHON_CLIENT) \
	  || python3 -m pip install -q --disable-pip-version-check --break-system-packages openapi-python-client==$(OPENAPI_PYTHON_CLIENT)

deps: web-deps browser octave spec-validator py-deps client-deps

test: deps test-spec test-rust test-web client-e2e schemathesis

# The committed spec is valid OpenAPI (tests/openapi.rs holds it to the router).
test-spec: spec-validator
	python3 -m openapi_spec_validator openapi.yaml

test-rust: py-deps
	cargo test --release --workspace

test-web:
	cargo build --release --bin seatrial
	cd web && SEATRIAL_BIN=../target/release/seatrial node --test tests/

# The contract as a generated client sees it: openapi-python-client builds a
# client from openapi.yaml (in a temp dir), and tests/python/client_e2e.py
# drives the real binary with it from vessel to exported model.
client-e2e: client-deps
	cargo build --release --bin seatrial
	SEATRIAL_BIN=$${CARGO_TARGET_DIR:-target}/release/seatrial bash tests/python/client_e2e.sh

fmt:
	cargo fmt --all

lint:
	cargo fmt --all -- --check
	cargo clippy --release --workspace --all-targets -- -D warnings

# The bounded-cost figures (issue 17) on loopback: a demo server on a temporary
# database, then 32 concurrent readers beside /api/health probes and an identify job.
LOAD_PORT ?= 8199
load-test:
	cargo build --release --bin seatrial --example load_test
	@tmp=$$(mktemp -d); \
	target/release/seatrial --demo --db $$tmp/load.db --listen 127.0.0.1:$(LOAD_PORT) --web-dir web --job-workers 1 >$$tmp/server.log 2>&1 & pid=$$!; \
	trap "kill $$pid 2>/dev/null; rm -rf $$tmp" EXIT; \
	for i in $$(seq 1 300); do curl -sf http://127.0.0.1:$(LOAD_PORT)/api/health >/dev/null && break; sleep 1; done; \
	target/release/examples/load_test --base http://127.0.0.1:$(LOAD_PORT) --clients 32 --seconds 20

# Schemathesis against the running service (pinned, in a venv under target/): every
# operation of openapi.yaml through its examples, coverage, fuzzing and stateful phases,
# bounded in time; any 5xx, undocumented status, content type or response schema fails.
# It signs in with an admin API token made at start (a generated Authorization header would
# only ever meet 401s). Schemathesis learns ids from responses and would soon demote, disable
# or revoke its own credentials, so user edits and token revokes get a second, short run
# of their own at the end. One worker: CPython 3.11's ast module is not thread-safe
# (gh-106905), and hypothesis parses source from its worker threads.
SCHEMATHESIS := 4.32.5
ST_VENV := target/py-schemathesis
ST_PORT ?= 8198
ST_SECONDS ?= 150
schemathesis:
	@[ -x $(ST_VENV)/bin/st ] && $(ST_VENV)/bin/st --version | grep -q "$(SCHEMATHESIS)" \
	  || { python3 -m venv $(ST_VENV) && $(ST_VENV)/bin/pip install -q --disable-pip-version-check schemathesis==$(SCHEMATHESIS); }
	cargo build --release --bin seatrial
	@tmp=$$(mktemp -d); \
	target/release/seatrial --db $$tmp/st.db --listen 127.0.0.1:$(ST_PORT) --web-dir web --job-workers 1 >$$tmp/server.log 2>&1 & pid=$$!; \
	trap "kill $$pid 2>/dev/null; rm -rf $$tmp" EXIT; \
	for i in $$(seq 1 60); do curl -sf http://127.0.0.1:$(ST_PORT)/api/health >/dev/null && break; sleep 1; done; \
	uid=$$(curl -sf -X POST -H 'Content-Type: application/json' -d '{"name":"schemathesis","role":"admin","password":"schemathesis-fuzz"}' \
	  http://127.0.0.1:$(ST_PORT)/api/users | python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])') \
	  && tok=$$(curl -sf -X POST -H 'Content-Type: application/json' -d "{\"name\":\"schemathesis\",\"user_id\":\"$$uid\"}" \
	  http://127.0.0.1:$(ST_PORT)/api/auth/tokens | python3 -c 'import json,sys; print(json.load(sys.stdin)["token"])') \
	  || { echo "could not create an admin API token for schemathesis"; exit 1; }; \
	st="$(CURDIR)/$(ST_VENV)/bin/st run $(CURDIR)/openapi.yaml --url http://127.0.0.1:$(ST_PORT) \
	  --checks not_a_server_error,status_code_conformance,content_type_conformance,response_schema_conformance \
	  --phases examples,coverage,fuzzing,stateful --max-examples 25 --workers 1 --seed 1 --no-color"; \
	self="--exclude-name 'PATCH /api/users/{id}' --exclude-name 'DELETE /api/auth/tokens/{id}'"; \
	cd $$tmp && eval $$st -H \"Authorization: Bearer $$tok\" --max-time $(ST_SECONDS) $$self \
	  && eval $$st -H \"Authorization: Bearer $$tok\" --max-time 30 $$(echo $$self | sed 's/--exclude-name/--include-name/g')

# cargo-fuzz (libFuzzer, nightly toolchain) on the log reader and the clock alignment,
# FUZZ_SECONDS each, seeded from the corpus kept in tests/fuzz/corpus; new finds go to
# target/fuzz-corpus (`make fuzz-merge` adds those that reach new code to the kept corpus).
CARGO_FUZZ := 0.13.1
FUZZ_SECONDS ?= 60
fuzz:
	@cargo fuzz --version 2>/dev/null | grep -q "$(CARGO_FUZZ)" || cargo install cargo-fuzz --version $(CARGO_FUZZ) --locked
	@for t in csv_reader alignment; do \
	  mkdir -p target/fuzz-corpus/$$t; \
	  cargo +nightly fuzz run --fuzz-dir tests/fuzz $$t target/fuzz-corpus/$$t tests/fuzz/corpus/$$t -- -max_total_time=$(FUZZ_SECONDS) -max_len=65536 || exit 1; \
	done

fuzz-merge:
	@for t in csv_reader alignment; do \
	  cargo +nightly fuzz run --fuzz-dir tests/fuzz $$t tests/fuzz/corpus/$$t target/fuzz-corpus/$$t -- -merge=1 || exit 1; \
	done
