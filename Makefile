# Everything a fresh machine needs, from the project's own files.
#   make demo   — install, then run the demo (writes demo-output/)
#   make test   — install, then every check: rustfmt, clippy, cargo test, ruff, mypy, pytest
PY ?= python3
PIP = $(PY) -m pip --disable-pip-version-check
CARGO ?= cargo
PYTEST_WORKERS ?= 2

.PHONY: install demo test lint rust-test py-test bench clean

install:
	$(PIP) install --quiet 'maturin>=1.7,<2'
	$(PIP) install --quiet --no-build-isolation -e '.[dev]'
	@# Debian's chromium drives the labelling app's browser test (Playwright cannot download its own).
	@command -v chromium >/dev/null 2>&1 || { if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	  || echo "note: could not install chromium; the labelling app's browser test will skip"; \
	else echo "note: chromium is not installed (needs root and apt-get); the labelling app's browser test will skip"; fi; }
	@# Videos of simulated runs: headless OpenGL (Mesa's EGL, OSMesa as fallback) and the ffmpeg that
	@# the imageio-ffmpeg wheel carries (without it videos are GIFs).
	@$(PY) -c "import imageio_ffmpeg" 2>/dev/null || $(PIP) install --quiet 'imageio-ffmpeg>=0.4' \
	  || echo "note: could not install imageio-ffmpeg; run videos will be GIFs"
	@if ! ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa\|libOSMesa'; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libegl1 libegl-mesa0 libgl1 libosmesa6 >/dev/null) \
	    || echo "note: could not install EGL/OSMesa; run videos will be skipped"; \
	  else echo "note: no headless OpenGL (EGL/OSMesa) and no root to install it; run videos will be skipped"; fi; fi

demo: install
	roughwalk demo --out-dir demo-output

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets --release -- -D warnings
	$(PY) -m ruff check python tests benchmarks examples
	$(PY) -m ruff format --check python tests benchmarks examples
	$(PY) -m mypy

rust-test:
	$(CARGO) test --release -p roughwalk-core

py-test:
	$(PY) -m pytest -n $(PYTEST_WORKERS) -q

test: install lint rust-test py-test

bench: install
	roughwalk bench --help

clean:
	rm -rf target demo-output python/roughwalk/_core*.so
