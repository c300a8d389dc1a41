# Hairloom: two entry points (see README.md).
#   make run   - the main job on the bundled sample
#   make test  - install what a fresh Debian machine lacks, then run every check
SHELL := /bin/bash
.DEFAULT_GOAL := run
CARGO ?= cargo
SAMPLE ?= assets/samples/head_long_wavy.hairloom
# wgpu's Vulkan loader wants a writable runtime dir; headless machines often have none.
export XDG_RUNTIME_DIR ?= /tmp/hairloom-runtime
# Tests that need a GPU adapter or the export validators fail (instead of skipping) under
# `make test`, which installs them.
export HAIRLOOM_REQUIRE_GPU ?= 1
export HAIRLOOM_REQUIRE_VALIDATORS ?= 1
export HAIRLOOM_REQUIRE_DISPLAY ?= 1

APT_PACKAGES := mesa-vulkan-drivers libvulkan1
# A virtual X display and a screenshot tool for the editor's window smoke test.
DISPLAY_PACKAGES := xvfb x11-apps
# Third-party validators of the exports: Khronos glTF-Validator and ktx-parse (npm, pinned in
# tools/validate/package-lock.json), Pixar's USD (PyPI usd-core) and the Alembic library (PyPI
# alembic3d) in a private venv.
VALIDATE_VENV := target/validate-venv
USD_CORE := usd-core==26.11
# The Alembic C++ library's Python bindings, to read .abc grooms back.
ALEMBIC3D := alembic3d==1.8.12.1

.PHONY: run test deps gpu-deps mesh-deps blender-deps toolchain lint samples bench fuzz

toolchain:
	@command -v $(CARGO) >/dev/null || { \
	  echo "Rust is not installed; installing it with rustup (needs curl and network)"; \
	  command -v curl >/dev/null || { apt-get update && apt-get install -y curl build-essential; }; \
	  curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal; \
	  echo "Rust installed: open a new shell or run 'source ~/.cargo/env', then run make again"; exit 1; }

# Installs Mesa's software Vulkan (lavapipe) so wgpu finds an adapter without a GPU.
gpu-deps:
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

# Mesa 25's lavapipe from bookworm-backports, unpacked under target/ and never installed: it
# has VK_EXT_mesh_shader (bookworm's Mesa 22.3 has not), so `make test` checks the
# mesh-shader generation path on the CPU too.
MESA_BACKPORT := $(CURDIR)/target/mesa-backport
mesh-deps:
	@[ -f $(MESA_BACKPORT)/lvp_icd.json ] || tools/mesa-backport.sh $(MESA_BACKPORT)

# gpu-deps plus the export validators.
deps: gpu-deps
	@missing=""; for p in $(DISPLAY_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ] && command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
	  echo "installing:$$missing"; apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	fi
	@tools=""; command -v npm >/dev/null || tools="$$tools nodejs npm"; \
	python3 -c 'import venv, ensurepip' 2>/dev/null || tools="$$tools python3-venv"; \
	if [ -n "$$tools" ] && command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
	  echo "installing:$$tools"; apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$tools >/dev/null; \
	fi
	@[ -d tools/validate/node_modules/gltf-validator ] || (cd tools/validate && npm ci --no-audit --no-fund --loglevel=error)
	@$(VALIDATE_VENV)/bin/python -c 'import pxr, alembic3d' 2>/dev/null || \
	  { python3 -m venv $(VALIDATE_VENV) && $(VALIDATE_VENV)/bin/pip install -q --disable-pip-version-check $(USD_CORE) $(ALEMBIC3D); }

# Blender (PyPI bpy) for the import check of our strand exports, in its own venv: bpy 5.3
# needs Python 3.13 (pyenv's where it exists), bpy 5.0.1 runs on Debian's 3.11; its wheels
# need a few X and GL libraries, installed as root. Success means `import bpy` works. Where
# it cannot install, this says why and the check is skipped (the reason is kept in
# target/bpy-venv.failed so the next run does not download again: delete it to retry);
# where bpy works, `make test` requires the check (HAIRLOOM_REQUIRE_BLENDER).
BPY_VENV := target/bpy-venv
BPY_APT := libx11-6 libxrender1 libxxf86vm1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libegl1
blender-deps:
	@if $(BPY_VENV)/bin/python -c 'import bpy' 2>/dev/null; then exit 0; fi; \
	if [ -f $(BPY_VENV).failed ]; then \
	  echo "warning: the Blender import check is skipped: $$(cat $(BPY_VENV).failed) (delete $(BPY_VENV).failed to retry)"; exit 0; fi; \
	mkdir -p $(dir $(BPY_VENV)); \
	missing=""; for p in $(BPY_APT); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ] && command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
	  echo "installing:$$missing"; apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; fi; \
	reason="no Python 3.13 or 3.11 was found"; \
	for py in python3.13 $$(ls -d $$HOME/.pyenv/versions/3.13*/bin/python3.13 2>/dev/null) python3.11 python3; do \
	  case "$$($$py -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)" in \
	    3.13) spec='bpy==5.3.*';; 3.11) spec='bpy==5.0.1';; *) continue;; esac; \
	  rm -rf $(BPY_VENV); \
	  if ! $$py -m venv $(BPY_VENV) >/dev/null 2>&1; then reason="$$py -m venv failed"; continue; fi; \
	  if ! $(BPY_VENV)/bin/pip install -q --disable-pip-version-check "$$spec"; then reason="pip could not install $$spec"; continue; fi; \
	  if err=$$($(BPY_VENV)/bin/python -c 'import bpy' 2>&1); then echo "installed $$spec for the Blender import check"; exit 0; fi; \
	  reason="$$spec installed but 'import bpy' failed: $$(echo "$$err" | tail -n 1)"; \
	done; \
	rm -rf $(BPY_VENV); echo "$$reason" > $(BPY_VENV).failed; \
	echo "warning: the Blender import check is skipped: $$reason"

RENDER_OUT ?= out/$(notdir $(SAMPLE:.hairloom=.png))

# With a display: the editor on the bundled sample. Without one: render the sample headless
# (software Vulkan when there is no GPU) and say where the picture is.
run: toolchain gpu-deps
	$(CARGO) build --release -p hairloom-editor
	@if [ -n "$$DISPLAY$$WAYLAND_DISPLAY" ]; then \
	  ./target/release/hairloom $(SAMPLE); \
	else \
	  echo "no display: rendering $(SAMPLE) headless"; \
	  ./target/release/hairloom check $(SAMPLE) && \
	  ./target/release/hairloom info $(SAMPLE) && \
	  ./target/release/hairloom render $(SAMPLE) --out $(RENDER_OUT) && \
	  echo "Rendered $(SAMPLE) to $(RENDER_OUT)"; \
	fi

# `cargo test --all-targets` builds examples as test harnesses, so the game example that
# render/tests/game_window.rs opens in a window is built as a program first.
# The mesh-shader tests, the game runtime (whose default is mesh shaders where the device
# has them) and the colour map on every ribbon input run again on Mesa 25's lavapipe, where
# the mesh tests must not skip.
test: toolchain deps mesh-deps blender-deps
	$(CARGO) build -p hairloom-render --example game
	if $(BPY_VENV)/bin/python -c 'import bpy' 2>/dev/null; then export HAIRLOOM_REQUIRE_BLENDER=1; fi; \
	  $(CARGO) test --workspace --all-targets
	$(CARGO) test --workspace --doc
	VK_ICD_FILENAMES=$(MESA_BACKPORT)/lvp_icd.json \
	  LD_LIBRARY_PATH=$(MESA_BACKPORT)/root/usr/lib/x86_64-linux-gnu \
	  HAIRLOOM_REQUIRE_MESH_SHADERS=1 $(CARGO) test -p hairloom-render --test strand_mesh --test game \
	    --test colour_map

lint: toolchain
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

samples: toolchain
	$(CARGO) run -p hairloom-core --example make_samples

# The benchmarks of BENCHMARKS.md. The lighting ones are long on a software adapter (about
# half an hour for `effects` at 100K strands and `shading` on lavapipe, 2 cores).
bench: toolchain gpu-deps
	$(CARGO) build --release -p hairloom-editor
	./target/release/hairloom bench interior
	./target/release/hairloom bench sim
	./target/release/hairloom bench effects --size 800x800 --runs 1
	./target/release/hairloom bench shading --size 320 --spp 64 --runs 1
	./target/release/hairloom bench far --size 256 --spp 32 --runs 1
	./target/release/hairloom bench fur --size 256 --spp 32 --runs 3

# Every fuzz target (project load, glTF import, runtime bundle, KTX2) for FUZZ_SECONDS each,
# optimised with overflow checks on (profile `fuzz`). A panic saves its input under
# fuzz/artifacts/ and fails. `make test` runs a bounded smoke pass of the same targets.
FUZZ_SECONDS ?= 120
fuzz: toolchain
	$(CARGO) build --profile fuzz -p hairloom-fuzz
	./target/fuzz/hairloom-fuzz run all --seconds $(FUZZ_SECONDS)
