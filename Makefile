# plume — the two commands of the README, and a few conveniences.
#   make demo   install missing Debian packages (as root), build, run `plume demo`
#   make test   the same setup, then every test through CTest
#   make viewer the browser viewer of `plume view` (node and npm; make build tries it too)
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: all deps configure build demo test bench install clean format viewer blender-addon

all: build

deps:
	@scripts/deps.sh

configure: deps
	@cmake -S . -B $(BUILD) $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)
	@scripts/viewer.sh $(BUILD) --optional

viewer: build
	@scripts/viewer.sh $(BUILD)

demo: build
	$(BUILD)/plume demo -o plume-demo

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b; done

install: build
	cmake --install $(BUILD)

# The Blender add-on (blender/), with the Python package and the presets inside.
blender-addon:
	/usr/bin/python3 blender/make_zip.py . $(BUILD)/plume_feathers.zip

format:
	clang-format -i include/plume/*.h src/*/*.c src/*/*.h cli/*.c cli/*.h tests/*.c tests/*.h bench/*.c

clean:
	rm -rf $(BUILD) build-asan plume-demo
