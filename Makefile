# hlvs-runner: two set-up commands on a fresh machine.
#   make scrimmage   set up what is missing, then play a match between two teams of stub robots
#   make test        set up what is missing, then run the whole test suite
# Each step is idempotent and skipped when its inputs have not changed.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
HLVS   := $(VENV)/bin/hlvs
BUILD  := .build
PYTEST_ARGS ?=
# pytest-xdist workers for `make test` (tests/conftest.py says what may run at once); 0: one process
TEST_WORKERS ?= 2

.PHONY: cluster scrimmage test setup venv system engine postgres gvisor images lint typecheck clean-build web

# What lint and typecheck read: they run again only when one of these changed.
CHECKED := pyproject.toml $(wildcard $(shell git ls-files --cached --others --exclude-standard '*.py' 2>/dev/null))

scrimmage: setup
	$(HLVS) scrimmage --out matches/scrimmage

test: setup postgres gvisor lint typecheck
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadgroup --no-loadscope-reorder $(PYTEST_ARGS)

setup: venv system engine images

venv: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@echo "==> virtual environment in $(VENV) (log: $(BUILD)/logs/pip.log)"
	@mkdir -p $(BUILD)/logs
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@: > $(BUILD)/logs/pip.log
	@# uv fetches the packages side by side (21 s here where pip took 57 s, the same versions);
	@# pip installs them when uv cannot be had or fails.
	@{ $(PY) -m pip install 'uv>=0.4,<1' && \
	   $(VENV)/bin/uv pip install --python $(PY) --compile-bytecode -e '.[dev,learn]'; \
	 } >> $(BUILD)/logs/pip.log 2>&1 || \
	 { echo "==> uv failed (see $(BUILD)/logs/pip.log): pip installs the environment"; \
	   $(PY) -m pip install -e '.[dev,learn]' >> $(BUILD)/logs/pip.log 2>&1; } || \
	 { tail -n 40 $(BUILD)/logs/pip.log; exit 1; }
	touch $@

# Host packages (Docker engine, registry, sshd, ffmpeg, OSMesa, mmdebstrap) on Debian/Ubuntu as root.
system: $(BUILD)/system.ok

$(BUILD)/system.ok: scripts/setup-system.sh
	@mkdir -p $(BUILD)
	bash scripts/setup-system.sh
	touch $@

# A Docker engine that answers; started here when installed but not running.
engine:
	@bash scripts/ensure-docker.sh

# Debian's PostgreSQL on 127.0.0.1 with a test role, for the service's tests (root only).
postgres: system
	@bash scripts/ensure-postgres.sh

# gVisor's runsc registered with the engine, for the tests that play robots under it (root only;
# without it they skip). Running containers are not touched.
gvisor: engine
	@bash scripts/ensure-gvisor.sh

# Content-tagged images: rebuilt only when their inputs change. BASE_IMAGE=python:3.11-slim uses
# a registry's base instead of the one made locally with mmdebstrap.
BASE_IMAGE ?=
images: venv engine
	$(HLVS) images build $(if $(BASE_IMAGE),--base $(BASE_IMAGE),)

lint: $(BUILD)/lint.ok

$(BUILD)/lint.ok: $(VENV)/.installed $(CHECKED)
	$(VENV)/bin/ruff check hlvs viewer service envs tournament cluster orchestrator simulator \
	  referee robot contracts benchmarks testkit examples tests
	$(VENV)/bin/lint-imports
	touch $@

typecheck: $(BUILD)/typecheck.ok

$(BUILD)/typecheck.ok: $(VENV)/.installed $(CHECKED)
	$(VENV)/bin/mypy
	touch $@

clean-build:
	rm -rf $(BUILD)

# The web front end (web/, TypeScript + three.js from the npm lock file) bundled into
# viewer/static/app.js, which is committed: installing the package needs no Node.js.
web:
	cd web && npm ci --no-audit --no-fund && npm run build

# A Slurm cluster on this machine (controller, accounting with MariaDB, five nodes in network
# namespaces) for the Slurm pool: `make cluster`, then HLVS_SERVICE_POOL=slurm hlvs serve.
cluster:
	bash scripts/ensure-slurm.sh up
