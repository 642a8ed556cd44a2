# `make help` lists the targets. The virtual environment .venv/ is made on first use.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# the results the docs and the README include; only the targets below write them
RESULTS := docs/results

.PHONY: help venv run test validate cluster-test tutorials bench speed figures accuracy melting dsmc readme docs lint wheel clean

help:  ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk -F':.*## ' '{printf "  %-13s %s\n", $$1, $$2}'

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# the documentation's tools, added to the environment when the docs are first built
DOCS_STAMP := $(VENV)/.installed-docs
$(DOCS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e '.[test,docs]'
	touch $(DOCS_STAMP)

venv: $(STAMP)  ## make the virtual environment and install sim into it (with the test tools)

run: $(STAMP)  ## run the default scene
	$(PY) -m sim

test: $(STAMP)  ## quick tests (long physics runs are marked slow), one worker per core; prints its wall time
	@start=$$(date +%s); status=0; $(PY) -m pytest -q -n logical --dist worksteal || status=$$?; \
	echo "make test: $$(( $$(date +%s) - start )) s of wall time (budget: 300 s on 2 cores)"; \
	exit $$status

validate: $(STAMP)  ## every test, slow physics runs included; the table into outputs/validation/ and docs/results/
	$(PY) -m pytest -q -m "not cluster" --hypothesis-profile=validate
	cp outputs/validation/table.md $(RESULTS)/validation.md

cluster-test: $(STAMP)  ## sweeps through a real SLURM of one node made here (as root: installs slurm-wlm, munge)
	$(PY) -m pytest -q -rs -p no:xdist -m cluster tests/cluster

tutorials: $(STAMP)  ## run the tutorial notebooks (nbmake)
	$(PY) -m pytest -q -p no:cacheprovider --nbmake --nbmake-timeout=600 docs/tutorials

figures: $(STAMP)  ## every figure into outputs/figures/, their web versions and the README's picture into docs/results/ (QUICK=1: small versions only)
	$(PY) -m sim.figures $(if $(QUICK),--quick)
	$(if $(QUICK),,$(PY) -m sim.figures.web --target $(RESULTS)/figures)
	$(if $(QUICK),,cp outputs/figures/fig08_crater_grid.png $(RESULTS)/crater.png)

accuracy: $(STAMP)  ## accuracy against wall time for every knob into outputs/accuracy_cost/ and docs/results/ (QUICK=1: fewer settings, not copied)
	$(PY) experiments/accuracy_cost/study.py $(if $(QUICK),--quick)
	$(if $(QUICK),,cp outputs/accuracy_cost/summary.md $(RESULTS)/accuracy.md)

melting: $(STAMP)  ## the equation of state through melting at the published sizes, into docs/results/ (hours of CPU, resumable: stopped, run it again; QUICK=1: a smoke run into outputs/)
	$(PY) experiments/melting/study.py $(if $(QUICK),--quick --out outputs/melting_quick --results outputs/melting_quick/results)
	$(if $(QUICK),,cp outputs/melting/results/melting.csv $(RESULTS)/melting.csv)
	$(if $(QUICK),,cp outputs/melting/results/melting_reference.csv $(RESULTS)/melting_reference.csv)
	$(if $(QUICK),,cp outputs/melting/results/melting.md $(RESULTS)/melting.md)
	$(if $(QUICK),,cp outputs/melting/results/melting.json $(RESULTS)/melting.json)
	$(if $(QUICK),,cp outputs/melting/results/melting_eos.png $(RESULTS)/melting_eos.png)
	$(if $(QUICK),,cp outputs/melting/results/melting_psi6.png $(RESULTS)/melting_psi6.png)
	$(if $(QUICK),,cp outputs/melting/results/melting_starts.png $(RESULTS)/melting_starts.png)

dsmc: $(STAMP)  ## the cooling states of rough disks by DSMC, the validation table's references, into docs/results/
	$(PY) -m sim.checks.dsmc --out $(RESULTS)/dsmc.json

bench: $(STAMP)  ## engine rate table (see benchmarks/engine_rate.py --help)
	$(PY) benchmarks/engine_rate.py

speed: $(STAMP)  ## sim beside the C code of the fastest design, in one session, into docs/results/
	$(PY) benchmarks/peer_speed.py --n 10000 100000 1000000 --phi 0.5 --state 16384:0.708 \
		--json $(RESULTS)/speed.json --markdown $(RESULTS)/speed.md
	$(PY) benchmarks/speed_figure.py $(RESULTS)/speed.json $(RESULTS)/speed.png

readme: $(STAMP)  ## the README's numbers made anew from docs/results/
	$(PY) docs/readme.py

docs: $(DOCS_STAMP)  ## the documentation site into outputs/site (mkdocs, warnings are errors)
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --quiet

lint: $(STAMP)  ## ruff over the sources and tests
	$(VENV)/bin/ruff check src tests benchmarks

# the throwaway install compiles into a numba cache of its own, removed with it
wheel: $(STAMP)  ## build the wheel and run the default scene from it in a fresh venv
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(PY) -m build --outdir "$$tmp/dist" . >"$$tmp/build.log" 2>&1 || { cat "$$tmp/build.log"; exit 1; }; \
	wheel=$$(ls "$$tmp"/dist/*.whl); echo "built $$(basename "$$wheel")"; \
	$(PYTHON) -m venv "$$tmp/venv"; \
	"$$tmp/venv/bin/python" -m pip install --quiet "$$wheel"; \
	mkdir "$$tmp/work"; cd "$$tmp/work"; \
	"$$tmp/venv/bin/sim" --help | grep -q "rough_cooling"; \
	NUMBA_CACHE_DIR="$$tmp/numba" "$$tmp/venv/bin/sim" stop.collisions=20000 \
		output.progress=false hydra.run.dir=run; \
	"$$tmp/venv/bin/sim-inspect" run/run.h5

clean:  ## remove the environment, caches and generated outputs
	rm -rf $(VENV) outputs .pytest_cache build dist src/*.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
