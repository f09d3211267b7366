# Two commands from a fresh clone: `make demo` and `make test`. Everything installs into .venv.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
export TI_SKIP_VERSION_CHECK := ON
# a bare `make` renders the demo, not only the venv (the first rule)
.DEFAULT_GOAL := demo

.PHONY: demo test goldens check-avx2 presets accuracy bench batch figures clean

$(BIN)/pendulum: pyproject.toml
	@# Taichi 1.7.4 has wheels for Python 3.9-3.13, this package needs 3.11: say so before a venv is made, and
	@# make it afresh where an earlier try left one of another Python (venv would keep that Python)
	@$(PYTHON) -c 'import sys; sys.exit(not (3, 11) <= sys.version_info[:2] <= (3, 13))' || { echo "make: \
	$(PYTHON) is missing or not Python 3.11 to 3.13, which this needs (Taichi 1.7.4's wheels): make \
	$(or $(MAKECMDGOALS),demo) PYTHON=python3.11" >&2; exit 2; }
	$(BIN)/python -c 'import sys; sys.exit(not (3, 11) <= sys.version_info[:2] <= (3, 13))' 2>/dev/null \
	|| $(PYTHON) -m venv --clear $(VENV)
	@# uv (from PyPI) installs the same packages as pip from the same index in a fraction of the time: 39 s
	@# against 3 min 36 s for this venv on a loaded 2-core machine, most of make test's set-up in CI
	$(BIN)/python -m pip install --quiet uv || echo "make: no uv; pip installs instead (slower)" >&2
	@# the distribution was called "pendulum" before; a venv holding both would have two owners of render/
	$(BIN)/python -m pip uninstall --quiet --yes pendulum 2>/dev/null || true
	@# --compile-bytecode: pip writes each package's .pyc files as it installs, uv does not, and where
	@# PYTHONDONTWRITEBYTECODE is set (as on these machines) Python then compiles taichi, numpy, scipy... from
	@# source in every process: 1.9 s of each import (3.4 s -> 1.4 s, median of 5), 1 s of a short render
	@# uv reads no pip.conf: where it fails or is missing (an index or proxy only pip is configured for), pip
	@# installs instead
	$(BIN)/uv pip install --quiet --compile-bytecode --python $(BIN)/python -e '.[test]' \
	|| $(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

demo: $(BIN)/pendulum
	$(BIN)/pendulum render rigid_chaos

# Two pytest workers (pytest-xdist): most of a test's time is compiling kernels and starting processes, which
# are single-threaded, so two workers keep both cores busy. Each test file runs whole on one worker, the files
# that share the preset renders together, the costliest first (tests/conftest.py: SHARE_A_WORKER, HEAVY_FIRST).
JOBS ?= 2
test: $(BIN)/pendulum
	$(BIN)/python -m pytest -n $(JOBS) --dist loadfile --durations=25

# After a deliberate visual change: rewrite tests/golden/ from the current renderer, then review and commit.
goldens: $(BIN)/pendulum
	$(BIN)/python -m pytest tests/test_golden.py tests/test_font.py --update-goldens -q

# The golden frames, tests/test_sincos.py and the state digests of tests/test_state_bits.py on an AVX2 CPU
# emulated by QEMU (apt-get install -y qemu-user), for a machine with AVX-512: slow, and not part of `make test`
# (docs/testing.md).
check-avx2: $(BIN)/pendulum
	$(BIN)/python tests/emulated_cpu.py --sincos --bits

presets: $(BIN)/pendulum
	$(BIN)/pendulum presets

accuracy: $(BIN)/pendulum
	$(BIN)/pendulum accuracy

bench: $(BIN)/pendulum
	$(BIN)/pendulum bench

batch: $(BIN)/pendulum
	$(BIN)/pendulum batch

# Measure, then put the figures into README.md and docs/*.md (generated blocks) and benchmarks/figures/. Run on a quiet machine.
figures: $(BIN)/pendulum
	$(BIN)/pendulum accuracy
	$(BIN)/pendulum render benchmarks/fractal_flip_readme.toml --no-progress
	$(BIN)/python benchmarks/seed_table.py
	$(BIN)/python benchmarks/effects.py --clock cpu --out out/bench/effects.md
	$(BIN)/python benchmarks/frame.py rigid_chaos --at 10 --out out/figures/hud_rigid_chaos.png
	$(BIN)/python benchmarks/frame.py rainbow_1000 --at 5 --out out/figures/glow_rainbow_1000.png
	$(BIN)/python benchmarks/frame.py poincare_shell --at 60 --size 1280x720 --out out/figures/poincare_shell.png
	$(BIN)/python benchmarks/compare_still.py
	$(BIN)/python benchmarks/readme_figures.py

clean:
	rm -rf $(VENV) out/*/ out/index.html *.egg-info
