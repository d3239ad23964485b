# The README's two commands: `make demo` (the main job on the simulated stand) and
# `make test` (the whole suite, as .ci/run does). Both build their own environment.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT := out
SYSTEM_TOOLS := mbpoll socat h5dump chromium

.PHONY: demo demo-plan test lint system-tools node-tools lock bench clean

$(STAMP): pyproject.toml requirements.lock
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.lock
	$(BIN)/python -m pip install --quiet --no-deps -e .
	touch $(STAMP)

# The main job on the simulated stand: the stand-sim with an effect switched on that the
# model lacks (a Maxwell branch in the fibre), two tests recorded over the real wire
# protocols, one replayed against the model, and both diagnosed (HTML report).
DEMO_EFFECT := fibre_viscoelastic
demo: $(STAMP)
	@mkdir -p $(OUT)
	$(BIN)/labstand run --backend sim --effect $(DEMO_EFFECT) --situation 11 --note "make demo" --force -o $(OUT)/run-11.mcap
	$(BIN)/labstand run --backend sim --effect $(DEMO_EFFECT) --situation 10 --note "make demo" --force -o $(OUT)/run-10.mcap
	$(BIN)/labstand replay $(OUT)/run-11.mcap --plot $(OUT)/replay-11.png --force
	$(BIN)/labstand diagnose $(OUT)/run-11.mcap $(OUT)/run-10.mcap --report $(OUT)/diagnosis --force

# One adaptive step (docs/planning.md): two gentle tests of a stand whose force channel
# lags 1 ms leave the diagnosis undecided (a gauge low-pass and a skew both delay the
# force); `labstand plan` searches the motions the safety prediction admits for the one
# that separates the rivals best and says by how much; that motion is run, and all three
# recordings are diagnosed again.
PLAN_EFFECT := channel_time_skew
PLAN_DIR := $(OUT)/plan
PLAN_RUN := $(BIN)/labstand run --backend sim --effect $(PLAN_EFFECT) --force
demo-plan: $(STAMP)
	@mkdir -p $(PLAN_DIR)
	$(PLAN_RUN) --signal trapezoidal --amplitude-mm 25 --frequency-hz 1.25 --cycles 4 --ramp-fraction 0.4 -o $(PLAN_DIR)/medium.mcap
	$(PLAN_RUN) --signal quasi-sinusoidal --amplitude-mm 60 --frequency-hz 0.5 --cycles 3 -o $(PLAN_DIR)/slow.mcap
	$(BIN)/labstand diagnose $(PLAN_DIR)/medium.mcap $(PLAN_DIR)/slow.mcap --json > $(PLAN_DIR)/diagnosis.json
	@$(BIN)/python -c 'import json, sys; d = json.load(open(sys.argv[1])); e = d["effects"]; \
	  print("first diagnosis:", d["verdict"], "-", ", ".join(x["effect"] + (" (indistinguishable from " + ", ".join(x["indistinguishable_from"]) + ")" if x["indistinguishable_from"] else "") for x in e) or "nothing named")' $(PLAN_DIR)/diagnosis.json
	$(BIN)/labstand plan --diagnosis $(PLAN_DIR)/diagnosis.json $(PLAN_DIR)/medium.mcap $(PLAN_DIR)/slow.mcap --force -o $(PLAN_DIR)/plan.json
	$(PLAN_RUN) --plan $(PLAN_DIR)/plan.json -o $(PLAN_DIR)/planned.mcap
	$(BIN)/labstand diagnose $(PLAN_DIR)/medium.mcap $(PLAN_DIR)/slow.mcap $(PLAN_DIR)/planned.mcap

# Debian tools the tests use as independent peers; installed here, never assumed.
system-tools:
	@missing=""; for t in $(SYSTEM_TOOLS); do command -v $$t >/dev/null || missing="$$missing $$t"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian tools for the tests:$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mbpoll socat hdf5-tools chromium >/dev/null; \
	fi

# The independent Foxglove WebSocket client of the live-view tests (@foxglove/ws-protocol,
# in Node; versions pinned by tests/live/node/package-lock.json).
NODE_CLIENT := tests/live/node
node-tools:
	@command -v npm >/dev/null || { echo "installing Node.js for the tests"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nodejs npm >/dev/null; }
	@[ -d $(NODE_CLIENT)/node_modules/@foxglove/ws-protocol ] || \
	  npm ci --prefix $(NODE_CLIENT) --no-audit --no-fund --silent

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports

test: $(STAMP) system-tools node-tools lint
	$(BIN)/python -m pytest -q

bench: $(STAMP) node-tools
	$(BIN)/python benchmarks/bench_model.py
	$(BIN)/python benchmarks/bench_live.py

lock: $(STAMP)
	$(BIN)/python -m pip freeze --exclude-editable | grep -v '^labstand' > requirements.lock.new
	mv requirements.lock.new requirements.lock

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .mypy_cache .ruff_cache $(NODE_CLIENT)/node_modules
