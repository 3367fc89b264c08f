# The two commands a newcomer needs (see README):
#   make run   – start the service with the demo campaigns on http://127.0.0.1:8080
#   make test  – install what the tests need, then run every test
# Everything builds and tests in release: debug builds run the numerics far slower.

SHELL := /bin/bash
.DEFAULT_GOAL := run
DB ?= data/seatrial.db
LISTEN ?= 127.0.0.1:8080

.PHONY: run test deps web-deps browser spec-validator py-deps client-deps test-rust test-spec test-web client-e2e fmt lint

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

deps: web-deps browser spec-validator py-deps client-deps

test: deps test-spec test-rust test-web client-e2e

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
