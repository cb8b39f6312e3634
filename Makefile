# DRT: distribution ray tracing for Blender.
#   make render      venv + render the default sample scene to out/ (SCENE=name for another one)
#   make test        venv + the whole test suite, a process per core (TESTS=path and PYTEST_ARGS=... to narrow
#                    it, TEST_JOBS= for one process)
#   make test-versions tests/core and tests/blender under each bpy of BPY_VERSIONS (4.2 5.0 5.2 LTS),
#                    each in its own venv (.venv-X.Y from requirements-X.Y.txt; 5.0 is .venv)
#   make extension   download the embreex wheels, validate, build the extension zips into dist/, the Linux
#                    one with compiled kernels (tools/ship_kernels.py; KERNELS= leaves them out)
#   make scenes      rebuild the sample .blend files from their scripts
#   make bench       DRT vs Cycles error against time (bench/run.py: bench/results/, bench/RESULTS.md,
#                    bench/plots/), then ray throughput and memory, instances, the ratio estimator and
#                    where a render's time goes per kernel (bench/render_time.py); about 30 minutes on 2 cores
#   make bench-throughput  only DRT vs raw Embree rays/s and peak memory (bench/throughput.py)
#   make bench-instances  a floor of 1,000 and 10,000 pebble instances, DRT vs Cycles time and memory
#                    (bench/instances.py: docs/performance.md)
#   make bench-ratio the ratio estimator against Monte Carlo: efficiency, bias, where the error is
#                    (bench/ratio_estimator.py: docs/ratio-estimator.md, bench/ratio_estimator.json); about 30 minutes
#   make bench-denoise built-in denoising: denoised vs noisy relMSE and the denoised error estimate against
#                    the true error (bench/denoise_figures.py --calibration: docs/denoising.md, bench/denoise_calibration.json)
#   make bench-farm  Dask per-task overhead, 2 local workers vs 1 process, N-machine model (bench/farm.py)
#   make texture-parity  DRT vs Cycles per procedural texture and mode (bench/texture_parity.py: docs/shader-node-parity.md)
#   make node-parity DRT vs Cycles per shader node case and closure (bench/node_parity.py: docs/shader-node-parity.md)
#   make sky-parity-4.2 the Sky Texture's cases against Blender 4.2's Cycles (Nishita; same page)
#   make scene-parity DRT vs Cycles per scene setting: shadows, visibility, holdout, catcher, linking, groups, cameras (bench/scene_parity.py: docs/scene-parity.md)
#   make gi-pair     the README's Cornell box with diffuse bounces, DRT and Cycles side by side (bench/gi_pair.py)
#   make venv        only create .venv (Python 3.11) with the pinned requirements
#   make clean       remove out/, dist/ and caches; make distclean also removes the venvs and wheels/
#   make blender-env build (once, cached in BLENDER_ENV) a Debian 13 root with Blender 4.3.2; needs root
#   make test-blender install the extension into that Blender and test it there (headless and GUI)

SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON311 ?= python3.11
PYTHON313 ?= python3.13
VENV := .venv
PY := $(VENV)/bin/python
# Written after a successful install; newer than requirements.txt means the venv is current.
STAMP := $(VENV)/.drt-requirements-installed

# The Blender version matrix of `make test-versions`: each a bpy wheel in a venv of its own, made from
# its own requirements file (5.0, the pinned default, is .venv from requirements.txt) with the Python
# that file names on its "# python: X.Y" line (PYTHON311 or PYTHON313 says which interpreter).
BPY_VERSIONS ?= 4.2 5.0 5.2
VERSION_TESTS ?= tests/core tests/blender
requirements_of = $(if $(filter 5.0,$1),requirements.txt,requirements-$1.txt)
venv_of = $(if $(filter 5.0,$1),$(VENV),$(VENV)-$1)
python_of = $(shell sed -n 's/^\# python: *\([0-9.]*\).*/\1/p' $1)

SCENE ?= cornell_box
OUT ?= out
DIST ?= dist
TESTS ?= tests
PYTEST_ARGS ?=
# make test's processes: one per core, each test module in one of them (its fixtures built once).
TEST_JOBS ?= -n auto --dist loadfile

# The wheels listed in the manifest are the single source of truth for what gets downloaded.
WHEELS := $(shell sed -n 's|^ *"\./\(wheels/[^"]*\.whl\)".*|\1|p' blender_manifest.toml)
STAGE := $(DIST)/.stage
# "ship": the Linux zip carries kernels compiled for it (Python 3.11, and 3.13 where BLENDER_ENV exists).
KERNELS ?= ship
# Blender's extension tool ships inside the bpy wheel; expanded when a recipe runs (after the venv exists).
BLENDER_EXT = $(PY) $(firstword $(wildcard $(VENV)/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py))

.PHONY: help venv render test test-versions extension scenes bench bench-throughput bench-instances bench-ratio bench-denoise bench-farm texture-parity node-parity sky-parity-4.2 scene-parity gi-pair clean distclean blender-env test-blender

help:
	@sed -n 's/^#   //p' Makefile

venv: $(STAMP)

$(STAMP): requirements.txt
	tools/venv.sh $(VENV) $< $(call python_of,$<) $(PYTHON$(subst .,,$(call python_of,$<)))
	@touch $@

# The other Blender versions' venvs: .venv-X.Y from requirements-X.Y.txt.
$(VENV)-%/.drt-requirements-installed: requirements-%.txt
	tools/venv.sh $(VENV)-$* $< $(call python_of,$<) $(PYTHON$(subst .,,$(call python_of,$<)))
	@touch $@

render: $(STAMP)
	@mkdir -p $(OUT)
	$(PY) -m drt_engine render sample_scenes/$(SCENE).blend -o $(OUT)/$(SCENE).exr
	$(PY) -m drt_engine render sample_scenes/$(SCENE).blend -o $(OUT)/$(SCENE).png

# pytest exits with 5 when it collects nothing; that is left as a failure on purpose:
# a suite that runs no test must not pass CI.
test: $(STAMP)
	$(PY) -m pytest $(TESTS) -q $(TEST_JOBS) $(PYTEST_ARGS)

# Every version runs even when one fails; the summary names the ones that failed.
test-versions: $(foreach v,$(BPY_VERSIONS),$(call venv_of,$v)/.drt-requirements-installed)
	@failed=; $(foreach v,$(BPY_VERSIONS),\
	  echo "== Blender $v: $(call venv_of,$v)/bin/python -m pytest $(VERSION_TESTS) -q $(PYTEST_ARGS)"; \
	  start=$$SECONDS; \
	  $(call venv_of,$v)/bin/python -m pytest $(VERSION_TESTS) -q $(PYTEST_ARGS) || failed="$$failed $v"; \
	  echo "== Blender $v: $$((SECONDS - start)) s";) \
	if [ -n "$$failed" ]; then echo "test-versions: failed under Blender$$failed" >&2; exit 1; fi

# One wheel per file name: embreex-VERSION-cpXY-cpXY-PLATFORM.whl gives pip its Python version and
# platform (the last tag of a compound manylinux platform).
wheels/%.whl: | $(STAMP)
	@mkdir -p wheels
	@IFS=- read -r dist version pytag abi platform <<< "$*"; \
	pyversion=$${pytag#cp}; pyversion=$${pyversion:0:1}.$${pyversion:1}; \
	echo "downloading $$dist $$version for Python $$pyversion, $${platform##*.}"; \
	$(PY) -m pip download --disable-pip-version-check --quiet --no-deps --only-binary=:all: \
	  --python-version $$pyversion --platform $${platform##*.} --dest wheels "$$dist==$$version"
	@test -f $@ || { echo "error: pip did not produce $@ (check the wheel name in blender_manifest.toml)" >&2; exit 1; }

# Blender wants the manifest and __init__.py at the root of the zip: stage the package, the manifest
# and the wheels in one folder, then let Blender's own tool validate and build it.
extension: $(WHEELS) | $(STAMP)
	@rm -rf $(STAGE) && mkdir -p $(STAGE)/wheels
	@cp -R drt_engine/. $(STAGE)/
	@cp blender_manifest.toml $(STAGE)/
	@cp $(WHEELS) $(STAGE)/wheels/
	$(BLENDER_EXT) validate $(STAGE)
	$(BLENDER_EXT) build --source-dir $(STAGE) --output-dir $(DIST) --split-platforms
	@rm -rf $(STAGE)
	$(if $(KERNELS),$(PY) tools/ship_kernels.py build $(DIST)/drt_engine-*-linux_x64.zip $(DIST)/.kernels $(BLENDER_ENV))
	@for zip in $(DIST)/drt_engine-*.zip; do $(BLENDER_EXT) validate "$$zip" || exit 1; done
	$(PY) bench/zip_sizes.py --dist $(DIST)

scenes: $(STAMP)
	@for script in sample_scenes/build_*.py; do echo "$(PY) $$script"; $(PY) "$$script" || exit 1; done

# throughput reads bench/run.py's fresh curves for its time-to-error columns, so it runs second
bench: $(STAMP)
	$(PY) bench/run.py --publish
	$(PY) bench/throughput.py
	$(PY) bench/instances.py
	$(PY) bench/ratio_estimator.py --publish
	$(PY) bench/render_time.py --publish

bench-throughput: $(STAMP)
	$(PY) bench/throughput.py

bench-instances: $(STAMP)
	$(PY) bench/instances.py

bench-ratio: $(STAMP)
	$(PY) bench/ratio_estimator.py --publish

bench-denoise: $(STAMP)
	$(PY) bench/denoise_figures.py --calibration

bench-farm: $(STAMP)
	$(PY) bench/farm.py

clean:
	rm -rf $(OUT) $(DIST) .pytest_cache
	find . -path './$(VENV)*' -prune -o -name __pycache__ -type d -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV) $(VENV)-* wheels

# A real Blender: Debian 13's Blender 4.3.2 in a debootstrap root kept outside the repository
# (about 1.5 GB, built once in under 3 minutes, reused while it exists).
BLENDER_ENV ?= /var/cache/drt/blender-trixie

blender-env:
	tools/blender-env.sh $(BLENDER_ENV)

# Runs tests/real_blender against the extension zip; tests/conftest.py collects that folder only
# when DRT_BLENDER_ENV names the root, so `make test` leaves it out.
test-blender: blender-env extension
	DRT_BLENDER_ENV=$(BLENDER_ENV) $(PY) -m pytest tests/real_blender -q $(PYTEST_ARGS)

texture-parity: $(STAMP)
	$(PY) bench/texture_parity.py

node-parity: $(STAMP)
	$(PY) bench/node_parity.py

sky-parity-4.2: $(VENV)-4.2/.drt-requirements-installed
	$(VENV)-4.2/bin/python bench/node_parity.py --sky

scene-parity: $(STAMP)
	$(PY) bench/scene_parity.py

gi-pair: $(STAMP)
	$(PY) bench/gi_pair.py
