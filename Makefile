# Hairloom: two entry points (see README.md).
#   make run   - the main job on the bundled sample
#   make test  - install what a fresh Debian machine lacks, then run every check
SHELL := /bin/bash
.DEFAULT_GOAL := run
CARGO ?= cargo
SAMPLE ?= assets/samples/head_long_wavy.hairloom
# wgpu's Vulkan loader wants a writable runtime dir; headless machines often have none.
export XDG_RUNTIME_DIR ?= /tmp/hairloom-runtime
# Tests that need a GPU adapter fail (instead of skipping) under `make test`, where
# lavapipe is installed.
export HAIRLOOM_REQUIRE_GPU ?= 1

APT_PACKAGES := mesa-vulkan-drivers libvulkan1

.PHONY: run test deps toolchain lint samples bench

toolchain:
	@command -v $(CARGO) >/dev/null || { \
	  echo "Rust is not installed; installing it with rustup (needs curl and network)"; \
	  command -v curl >/dev/null || { apt-get update && apt-get install -y curl build-essential; }; \
	  curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal; \
	  echo "Rust installed: open a new shell or run 'source ~/.cargo/env', then run make again"; exit 1; }

# Installs Mesa's software Vulkan (lavapipe) so wgpu finds an adapter without a GPU.
deps:
	@mkdir -p "$(XDG_RUNTIME_DIR)" && chmod 700 "$(XDG_RUNTIME_DIR)"
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  if command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
	    echo "installing:$$missing"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	  else \
	    echo "warning: missing$$missing (install them as root for the software GPU adapter)"; \
	  fi; \
	fi

run: toolchain
	$(CARGO) build --release -p hairloom-editor
	./target/release/hairloom check $(SAMPLE)
	./target/release/hairloom info $(SAMPLE)

test: toolchain deps
	$(CARGO) test --workspace --all-targets
	$(CARGO) test --workspace --doc

lint: toolchain
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

samples: toolchain
	$(CARGO) run -p hairloom-core --example make_samples

bench: toolchain
	$(CARGO) build --release -p hairloom-editor
	./target/release/hairloom bench interior
