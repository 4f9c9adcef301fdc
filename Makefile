# The two commands of README.md. Each installs whatever is missing first (tools/setup.sh).
.PHONY: setup dev demo test bench

setup:
	@bash tools/setup.sh

# For developers: the same .venv with alight installed editable (app/ mapped to the name alight).
dev: setup
	.venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[test]"

# The main job on built-in defaults: the default material ball in the built-in studio.
demo: setup
	.venv/bin/alight render --out alight-demo.png

# The test suite, headless (EGL; the editor's tests start their own Xvfb).
test: setup
	bash tools/run_tests.sh

bench: setup
	.venv/bin/python benchmarks/bench_render.py
