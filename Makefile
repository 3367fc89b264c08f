# The two commands a newcomer needs (see README):
#   make run   – start the service with the demo campaigns on http://127.0.0.1:8080
#   make test  – install what the tests need, then run every test
# Everything builds and tests in release: debug builds run the numerics far slower.

SHELL := /bin/bash
.DEFAULT_GOAL := run
DB ?= data/seatrial.db
LISTEN ?= 127.0.0.1:8080

.PHONY: run test deps web-deps browser test-rust test-web fmt lint

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

deps: web-deps browser

test: deps test-rust test-web

test-rust:
	cargo test --release --workspace

test-web:
	cargo build --release --bin seatrial
	cd web && SEATRIAL_BIN=../target/release/seatrial node --test tests/

fmt:
	cargo fmt --all

lint:
	cargo fmt --all -- --check
	cargo clippy --release --workspace --all-targets -- -D warnings
