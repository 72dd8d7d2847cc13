# surfblend build. `make run` and `make test` work on a fresh Debian machine: missing Debian
# packages are installed when run as root (apt-get), otherwise the exact list is printed.

CC      ?= cc
CXX     ?= c++
OPT     ?= -O2
CFLAGS  ?= -std=c99 $(OPT) -g -Wall -Wextra -pedantic
CXXFLAGS?= -std=c++14 $(OPT) -g -Wall -Wextra
SAN     ?=
BUILD   ?= build
LIBS    := -lm -lpthread -ldl
SHAPES  ?= ../shared/peers/opensubdiv-shapes
REAL_MESHES ?= $(dir $(SHAPES))real-meshes

SRC_MODULES := src/sfb_api.h src/sfb_internal.h $(wildcard src/*.c src/patch/*.c src/fillet/*.c)
TEST_SRCS   := $(wildcard tests/test_*.c)
BACKEND_HDRS:= $(wildcard backends/*.h backends/*/*.h backends/*/glsl/*.glsl)
EXAMPLES    := $(patsubst examples/%.c,$(BUILD)/examples/%,$(wildcard examples/*.c))
# C++ examples (examples/03_engine.cpp: an engine that owns its EGL context, links EGL and GL itself)
EXAMPLES_CXX:= $(patsubst examples/%.cpp,$(BUILD)/examples/%,$(wildcard examples/*.cpp))
# Test programs that play a GL host link EGL and GL themselves (the library never does).
GL_LIBS     := -lEGL -lGL
# The benchmark: OpenSubdiv's CPU evaluators (its OmpEvaluator is in Debian's libosdCPU, built
# with OpenMP) and its GL compute evaluator (libosdGPU) on an EGL context the benchmark makes.
BENCH_LIBS  := -losdGPU -losdCPU $(GL_LIBS)

# Debian packages each goal needs (the library itself needs none but a C compiler).
# Tests: OpenSubdiv (oracle, benchmark), Criterion; for the gl/osmesa backends at run time the
# EGL loader (libegl1), Mesa's EGL and software drivers (libegl-mesa0, libgl1-mesa-dri: llvmpipe)
# and libOSMesa (libosmesa6); to build tests/gl_host.c and the benchmark the EGL/GL headers and
# link libraries (libegl-dev, libgl-dev: EGL/egl.h, GL/glcorearb.h, libEGL.so, libGL.so);
# glslangValidator (glslang-tools) for tools/check_glsl.sh.
PKGS_BASE := $(if $(shell command -v cc 2>/dev/null),,build-essential)
PKGS_TEST := g++ libosd-dev libcriterion-dev pkg-config \
             libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6 libegl-dev libgl-dev glslang-tools
# The CLI writes PNG pictures (surfblend render) with stb_image_write (libstb-dev, headers only).
PKGS_CLI  := libstb-dev
# The glTF export tool (tools/sfb2gltf.cpp, C++17): tinygltf (Debian ships it as a library, with
# nlohmann-json for its JSON) and meshoptimizer.
PKGS_GLTF := g++ libtinygltf-dev nlohmann-json3-dev libmeshoptimizer-dev
GLTF_LIBS := -ltinygltf -lmeshoptimizer
# The C++ examples: GLM (headers only), the EGL/GL headers and link libraries (the engine example
# is a GL host), g++; they write PNG with stb_image_write (PKGS_CLI).
PKGS_EXAMPLES := g++ libglm-dev libegl-dev libgl-dev
PKGS_FUZZ := clang libclang-rt-14-dev
# The NEON kernels, cross-compiled for AArch64 and run under qemu user emulation (make test-neon).
PKGS_NEON := gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user-static
# The web checks (tests/web/): Chromium for three.js in a real headless browser, Node and npm for
# the Khronos glTF validator, three.js and the browser driver (playwright-core). Node and npm
# are only asked for when their commands are missing (a Node from elsewhere is fine: >= 18).
PKGS_WEB  := chromium $(if $(shell command -v node 2>/dev/null),,nodejs) $(if $(shell command -v npm 2>/dev/null),,npm)
# npm packages of the web checks, installed by `npm ci` from the committed package.json and
# package-lock.json (tests/web/) into NODE_DIR; the scripts find them there (SFB_NODE_DIR).
NODE_DIR  ?= $(BUILD)/node

.PHONY: deps-web test-web install uninstall
.PHONY: all run test check-modules test-neon deps-neon bench fuzz asan amalgamate amalgamate-check embed-glsl deps deps-test deps-examples deps-fuzz clean unit-build

all: $(BUILD)/surfblend $(BUILD)/sfb2gltf $(EXAMPLES) $(EXAMPLES_CXX)

define need_pkgs
	@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing Debian packages:$$missing"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	  else \
	    echo "missing Debian packages:$$missing"; echo "install them with: sudo apt-get install$$missing"; exit 1; \
	  fi; \
	fi
endef

deps:
	$(call need_pkgs,$(PKGS_BASE) $(PKGS_CLI) $(PKGS_GLTF))
deps-test:
	$(call need_pkgs,$(PKGS_BASE) $(PKGS_CLI) $(PKGS_GLTF) $(PKGS_TEST) $(PKGS_EXAMPLES))
deps-examples:
	$(call need_pkgs,$(PKGS_BASE) $(PKGS_CLI) $(PKGS_EXAMPLES))
deps-fuzz:
	$(call need_pkgs,$(PKGS_FUZZ))
deps-neon:
	$(call need_pkgs,$(PKGS_NEON))
deps-web:
	$(call need_pkgs,$(PKGS_WEB))
	@$(MAKE) --no-print-directory $(NODE_DIR)/.installed

# (re-run when the lock file changes; npm ci installs exactly what it lists)
$(NODE_DIR)/.installed: tests/web/package.json tests/web/package-lock.json
	@mkdir -p $(NODE_DIR)
	cp tests/web/package.json tests/web/package-lock.json $(NODE_DIR)/
	cd $(NODE_DIR) && npm ci --no-audit --no-fund --loglevel=error
	@touch $@

# ---- the single header ----
amalgamate:
	./tools/amalgamate.sh > surfblend.h.tmp && mv surfblend.h.tmp surfblend.h

# GLSL sources of the gl backend embedded as C strings (tools/check_glsl.sh checks it is current)
embed-glsl:
	./tools/embed_glsl.sh > backends/gl/shaders.h.tmp && mv backends/gl/shaders.h.tmp backends/gl/shaders.h

# The library from src/*.c as separate translation units (C99 and C++), linked with the examples
# and run: module interfaces are declared in src/sfb_internal.h, the amalgamation order is not
# load-bearing (tools/check_modules.sh; part of make test).
check-modules:
	CC="$(CC)" CXX="$(CXX)" ./tools/check_modules.sh $(BUILD)

amalgamate-check:
	@./tools/amalgamate.sh > $${TMPDIR:-/tmp}/surfblend.h.check && \
	if cmp -s $${TMPDIR:-/tmp}/surfblend.h.check surfblend.h; then echo "amalgamate-check: surfblend.h is up to date"; \
	else echo "amalgamate-check: FAILED: surfblend.h is stale against src/ (run 'make amalgamate')"; exit 1; fi

# ---- library, CLI, examples ----
$(BUILD)/libsfb.o: tools/impl.c surfblend.h $(BACKEND_HDRS)
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(SAN) -I. -c -x c tools/impl.c -o $@

# The same library with its module interfaces (src/sfb_internal.h) of external linkage, for the
# white-box suites; in libsfb.o they are static, inlined across modules.
$(BUILD)/libsfb_internal.o: tools/impl.c surfblend.h $(BACKEND_HDRS)
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(SAN) -DSURFBLEND_EXPOSE_INTERNALS -I. -c -x c tools/impl.c -o $@

# What the command-line tools share (tools/cli_common.h: C99 and C++14).
$(BUILD)/cli_common.o: tools/cli_common.c tools/cli_common.h surfblend.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(SAN) -I. -c tools/cli_common.c -o $@

# (order-only: the CLI needs stb_image_write from PKGS_CLI; deps installs it, or names it)
$(BUILD)/surfblend: tools/surfblend.c tools/cli_common.h $(BUILD)/cli_common.o $(BUILD)/libsfb.o | deps
	$(CC) $(CFLAGS) $(SAN) -I. tools/surfblend.c $(BUILD)/cli_common.o $(BUILD)/libsfb.o -o $@ $(LIBS)

$(BUILD)/sfb2gltf: tools/sfb2gltf.cpp tools/cli_common.h $(BUILD)/cli_common.o $(BUILD)/libsfb.o | deps
	$(CXX) $(subst -std=c++14,-std=c++17,$(CXXFLAGS)) $(SAN) -I. -Itools tools/sfb2gltf.cpp $(BUILD)/cli_common.o $(BUILD)/libsfb.o -o $@ $(GLTF_LIBS) $(LIBS)

# reads sfb2gltf's files back (tinygltf) and compares them with the library (tests/gltf_test.sh)
$(BUILD)/gltf_check: tests/gltf_check.cpp tests/harness.h $(BUILD)/libsfb.o | deps
	$(CXX) $(subst -std=c++14,-std=c++17,$(CXXFLAGS)) $(SAN) -I. tests/gltf_check.cpp $(BUILD)/libsfb.o -o $@ $(GLTF_LIBS) $(LIBS)

# (order-only: examples/04_tribezier_panel.c writes PNG with stb_image_write, PKGS_CLI)
$(BUILD)/examples/%: examples/%.c $(BUILD)/libsfb.o | deps
	@mkdir -p $(BUILD)/examples
	$(CC) $(CFLAGS) $(SAN) -I. $< $(BUILD)/libsfb.o -o $@ $(LIBS)

# C++ examples (GLM, stb_image_write); the engine example is a GL host and links EGL and GL itself
# (order-only: the packages of PKGS_EXAMPLES)
$(BUILD)/examples/%: examples/%.cpp tests/egl_host.h $(BUILD)/libsfb.o | deps-examples
	@mkdir -p $(BUILD)/examples
	$(CXX) $(CXXFLAGS) $(SAN) -I. $< $(BUILD)/libsfb.o -o $@ $(GL_LIBS) $(LIBS)

run: deps $(BUILD)/surfblend $(BUILD)/sfb2gltf $(BUILD)/examples/04_tribezier_panel $(BUILD)/examples/05_reflection_panel \
     $(BUILD)/examples/06_fillet_panel
	@mkdir -p out
	./$(BUILD)/surfblend info examples/data/creased_box.obj
	./$(BUILD)/surfblend refine --scheme catmark --level 3 --limit examples/data/creased_box.obj -o out/creased_box_level3.obj
	@echo "wrote out/creased_box_level3.obj"
	@# subdivision shading (seed 001): the blended normals, and highlight lines of the limit normals
	@# (before) and of the blended ones (after), seen along the diagonal of a smooth corner
	@# (an extraordinary vertex of valence 3, at the middle of the picture)
	./$(BUILD)/surfblend shade --scheme catmark --level 3 examples/data/creased_box.obj -o out/creased_box_shaded.obj
	./$(BUILD)/surfblend render --highlight --normals limit --view -116.6,33.8 --zoom 1.3 --stripes 6 --size 800x600 \
	  examples/data/creased_box.obj -o out/creased_box_before.png
	./$(BUILD)/surfblend render --highlight --normals blended --view -116.6,33.8 --zoom 1.3 --stripes 6 --size 800x600 \
	  examples/data/creased_box.obj -o out/creased_box_after.png
	./$(BUILD)/surfblend render --blend-weights --view -116.6,33.8 --size 800x600 examples/data/creased_box.obj -o out/creased_box_weights.png
	@echo "wrote out/creased_box_shaded.obj out/creased_box_before.png out/creased_box_after.png out/creased_box_weights.png"
	@# the same pair for OpenSubdiv's catmark_pole8 (one vertex of valence 8), seen from above
	@if [ -d "$(SHAPES)" ]; then \
	  for n in limit:before blended:after; do \
	    echo "./$(BUILD)/surfblend render --level 4 --highlight --normals $${n%%:*} --view 20,60 --zoom 1.2 --size 800x600 $(SHAPES)/catmark_pole8.obj -o out/catmark_pole8_$${n##*:}.png"; \
	    ./$(BUILD)/surfblend render --level 4 --highlight --normals $${n%%:*} --view 20,60 --zoom 1.2 --size 800x600 \
	      $(SHAPES)/catmark_pole8.obj -o out/catmark_pole8_$${n##*:}.png || exit 1; \
	  done; \
	  echo "wrote out/catmark_pole8_before.png out/catmark_pole8_after.png"; \
	else echo "peer shapes not found at $(SHAPES): the catmark_pole8 pictures are skipped"; fi
	@# manifold-based blending (seed 000): a surface with a crease loop, a corner and darts (as the
	@# seed's Fig. 14), tessellated to OBJ and drawn; and a torus trimmed by a disc mask on every
	@# face (as Fig. 11)
	./$(BUILD)/surfblend tess --scheme manifold --rate 12 examples/data/manifold_features.obj -o out/manifold_features.obj
	./$(BUILD)/surfblend render --scheme manifold --rate 16 --view 35,30 --size 800x600 examples/data/manifold_features.obj \
	  -o out/manifold_features.png
	./$(BUILD)/surfblend render --scheme manifold --rate 8 --trim examples/data/trim_disc.png --view 35,30 --size 800x600 \
	  examples/data/torus.obj -o out/manifold_trimmed.png
	@echo "wrote out/manifold_features.obj out/manifold_features.png out/manifold_trimmed.png"
	@# quartic triangular Bezier surfaces (seed 004): a straight crease through a vertex of valence 5
	@# at s = 0 (smooth, G1), 0.5 and 1 (the crease), with highlight lines (as the seed's Fig. 9)
	@for s in 0 0.5 1; do \
	  ./$(BUILD)/surfblend render --scheme tribezier --sharpness $$s --rate 12 --highlight --view 30,50 --size 600x450 \
	    examples/data/tribezier_crease_v5.obj -o out/tribezier_crease_v5_s$$s.png || exit 1; done
	@echo "wrote out/tribezier_crease_v5_s0.png out/tribezier_crease_v5_s0.5.png out/tribezier_crease_v5_s1.png"
	@# the seed's Figs. 8-11 as one panel: a crease at valence 4, 5 and 7 and a corner at valence 3
	@# (meshes built in the program), each at s = 0, 0.5 and 1, with highlight lines
	./$(BUILD)/examples/04_tribezier_panel out/tribezier_panel.png
	@# surface quality (seed 003), evaluated exactly per pixel: the seed's Fig. 7 as one panel (reflection
	@# lines from proxies subdivided once, twice, three times; top the polygon-based method, bottom ours),
	@# the close-up of Fig. 8 and a mean-curvature map of the creased box; then the analysis command on a
	@# real mesh (spot, a Loop surface): reflection lines, zebra and the Gaussian curvature
	./$(BUILD)/examples/05_reflection_panel out
	@if [ -f "$(REAL_MESHES)/spot.obj" ]; then \
	  for m in reflection zebra curvature; do \
	    echo "./$(BUILD)/surfblend analyze --scheme loop --mode $$m --size 800x600 $(REAL_MESHES)/spot.obj -o out/spot_$$m.png"; \
	    ./$(BUILD)/surfblend analyze --scheme loop --mode $$m --size 800x600 $(REAL_MESHES)/spot.obj -o out/spot_$$m.png || exit 1; \
	  done; \
	else echo "real meshes not found at $(REAL_MESHES): the spot pictures are skipped"; fi
	@# rolling-ball fillets (seed 002, as its Fig. 12): a box with a cylinder on top, every feature by
	@# dihedral angle -- the concave seam, the cylinder's rim, the box's edges and corners -- at r = 0.15
	@# and 0.25; before and after with highlight lines, mean curvature and close-ups; prints mean |H|,
	@# sharpest edges, folds and linkage normal jumps
	./$(BUILD)/examples/06_fillet_panel out/fillet_panel.png
	@# the main job's end: glTF 2.0 for engines and viewers -- the creased box with subdivision-shading
	@# normals (hard edges split), and the manifold blend tessellated
	./$(BUILD)/sfb2gltf --level 3 examples/data/creased_box.obj -o out/creased_box.glb
	./$(BUILD)/sfb2gltf --scheme manifold --tess 16 examples/data/manifold_features.obj -o out/manifold_features.glb
	@for f in out/creased_box.glb out/manifold_features.glb; do echo "wrote $$f ($$(wc -c < $$f) bytes)"; done

# ---- tests ----
$(BUILD)/unit: $(TEST_SRCS) $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. $(TEST_SRCS) $(BUILD)/libsfb.o -o $@ -lcriterion $(LIBS)

$(BUILD)/osd_agree: tests/osd_agree.cpp $(BUILD)/libsfb.o
	$(CXX) $(CXXFLAGS) $(SAN) -I. tests/osd_agree.cpp $(BUILD)/libsfb.o -o $@ -losdCPU $(LIBS)

# Silhouette IoU of two PNGs, for the engine example's test (tests/engine_test.sh; stb_image).
$(BUILD)/png_iou: tests/png_iou.c | deps
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(SAN) tests/png_iou.c -o $@ -lm

# Backend agreement (every optional backend against ref): links the library alone.
$(BUILD)/agree: tests/agree.c tests/harness.h $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/agree.c $(BUILD)/libsfb.o -o $@ $(LIBS)

# The engine case: the test is the GL host, so it links EGL and GL itself.
$(BUILD)/gl_host: tests/gl_host.c tests/harness.h tests/egl_host.h $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/gl_host.c $(BUILD)/libsfb.o -o $@ $(GL_LIBS) $(LIBS)

# Failure paths of gl/osmesa: compiles its own implementation with overrides (tests/gl_errors.c).
$(BUILD)/gl_errors: tests/gl_errors.c tests/harness.h surfblend.h $(BACKEND_HDRS)
	$(CC) $(CFLAGS) $(SAN) -I. tests/gl_errors.c -o $@ $(LIBS)

# Table pieces and split dispatches of gl/osmesa, under tiny limits (tests/gl_pieces.c).
$(BUILD)/gl_pieces: tests/gl_pieces.c tests/harness.h surfblend.h $(BACKEND_HDRS)
	$(CC) $(CFLAGS) $(SAN) -I. tests/gl_pieces.c -o $@ $(LIBS)

# Limit evaluation (sfb_surface_eval) on every backend: exactness, invariance, derivatives,
# continuity, normals at extraordinary vertices (tests/limit.c).
$(BUILD)/limit: tests/limit.c tests/harness.h $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/limit.c $(BUILD)/libsfb.o -o $@ $(LIBS)

# The Stam eigen structures, checked against the subdivision matrices: reaches the builders
# through src/sfb_internal.h, linked from libsfb_internal.o as the suites below (tests/eigen.c).
$(BUILD)/eigen: tests/eigen.c tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/eigen.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Subdivision shading (sfb_surface_shade) on every backend: weights, variants, darts, split
# normals, smoothness at extraordinary vertices; reads the refined level's vertex rules through
# src/sfb_internal.h (tests/shade.c).
$(BUILD)/shade: tests/shade.c tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/shade.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Trimming of tessellations with a mask (sfb_surface_tessellate) on every backend: kept areas,
# the cut on the contour, watertightness, atlases, agreement, bad masks, failing allocations
# (tests/trim.c).
$(BUILD)/trim: tests/trim.c tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/trim.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# The finish_normals kernel of every backend against ref, degenerate inputs included: compiles the
# library in (gl under a 64 KiB block limit, so its calls run in batches) and reaches the backend
# vtables directly (tests/finish_normals.c).
$(BUILD)/finish_normals: tests/finish_normals.c tests/harness.h surfblend.h $(BACKEND_HDRS)
	$(CC) $(CFLAGS) $(SAN) -I. tests/finish_normals.c -o $@ $(LIBS)

# Seed 003's shade and raster kernels of every backend (each simd instruction set) against ref
# on random jobs: simd bit for bit, gl/osmesa within float (tests/analysis_kernels.c).
$(BUILD)/analysis_kernels: tests/analysis_kernels.c tests/harness.h surfblend.h $(BACKEND_HDRS)
	$(CC) $(CFLAGS) $(SAN) -I. tests/analysis_kernels.c -o $@ $(LIBS)

# Manifold-based blending (SFB_SCHEME_MANIFOLD_BLEND) on every backend: interpolation, continuity,
# creases/darts/corners, derivatives, agreement; reaches the patch table through
# src/sfb_internal.h (tests/manifold.c).
$(BUILD)/manifold: tests/manifold.c tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/manifold.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Quartic triangular Bezier surfaces (SFB_SCHEME_TRIBEZIER, seed 004): G1, Loop where regular,
# creases and the s-blend, the undulation measurement, every backend's eval; reaches the builder's
# double points through src/sfb_internal.h (tests/tribezier.c).
$(BUILD)/tribezier: tests/tribezier.c tests/tribezier_mesh.h tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/tribezier.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Surface quality analysis (sfb_surface_analyze, seed 003) on every backend: analytic paraboloid
# and saddle, level independence, no gaps, agreement with ref, bad configurations (tests/analyze.c).
$(BUILD)/analyze: tests/analyze.c tests/harness.h $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/analyze.c $(BUILD)/libsfb.o -o $@ $(LIBS)

# The rolling-ball operator's geometry modules on their own: AABB tree, triangle-triangle
# intersection, sparse conjugate gradients, mesh normals and mean curvature (tests/geom.c).
$(BUILD)/geom: tests/geom.c tests/harness.h src/sfb_internal.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/geom.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Rolling-ball fillets (sfb_mesh_fillet, seed 002): exact quarter cylinders, conics, sharpening,
# the cylinder-box seam, self-intersection, bad input (tests/fillet.c, shapes from
# examples/fillet_shapes.h).
$(BUILD)/fillet: tests/fillet.c tests/harness.h examples/fillet_shapes.h $(BUILD)/libsfb_internal.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/fillet.c $(BUILD)/libsfb_internal.o -o $@ $(LIBS)

# Manifold blending on gl/osmesa and the vertex-shader draw path (with trimming) on a GL context
# the test owns (links EGL/GL as gl_host) (tests/gl_manifold.c).
$(BUILD)/gl_manifold: tests/gl_manifold.c tests/harness.h tests/egl_host.h $(BUILD)/libsfb.o
	$(CC) $(CFLAGS) $(SAN) -I. tests/gl_manifold.c $(BUILD)/libsfb.o -o $@ $(GL_LIBS) $(LIBS)

# The web checks' silhouette comparer (stb_image from PKGS_CLI) (tests/web/png_iou.c).
$(BUILD)/web/png_iou: tests/web/png_iou.c | deps
	@mkdir -p $(BUILD)/web
	$(CC) -std=c99 $(OPT) -g -Wall -Wextra $(SAN) $< -o $@ -lm

unit-build: $(BUILD)/web/png_iou $(BUILD)/surfblend $(BUILD)/unit $(BUILD)/osd_agree $(BUILD)/agree $(BUILD)/limit $(BUILD)/eigen $(BUILD)/gl_host \
            $(BUILD)/gl_errors $(BUILD)/gl_pieces $(BUILD)/shade $(BUILD)/trim $(BUILD)/finish_normals $(BUILD)/analysis_kernels $(BUILD)/manifold $(BUILD)/tribezier $(BUILD)/analyze $(BUILD)/geom $(BUILD)/fillet $(BUILD)/gl_manifold $(EXAMPLES) \
            $(EXAMPLES_CXX) $(BUILD)/png_iou $(BUILD)/sfb2gltf $(BUILD)/gltf_check

# On CI (CI set and not false/0) the optional backends must run, not be skipped: the suites
# fail for a backend in SFB_REQUIRE_BACKENDS that is unavailable. CI has Mesa llvmpipe and
# OSMesa but no GPU. A value already in the environment wins. The programs build JOBS at a time
# and the suites run JOBS side by side (tests/run_all.sh prints each one's wall time).
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
# The web checks' packages (deps-web) are installed too, but a failure there (not root, offline)
# only makes the web suites skip, with the reason; on CI they must run (SFB_REQUIRE_WEB).
test: deps-test amalgamate-check
	@$(MAKE) --no-print-directory deps-web || echo "make deps-web failed: the web suites will be skipped (on CI: failed)"
	$(MAKE) --no-print-directory -j$(JOBS) unit-build
	@if [ -n "$${CI:-}" ] && [ "$${CI}" != false ] && [ "$${CI}" != 0 ]; then \
	  export SFB_REQUIRE_BACKENDS="$${SFB_REQUIRE_BACKENDS:-simd,gl,osmesa}"; \
	  export SFB_REQUIRE_WEB="$${SFB_REQUIRE_WEB:-1}"; \
	  echo "CI=$${CI}: SFB_REQUIRE_BACKENDS=$${SFB_REQUIRE_BACKENDS} SFB_REQUIRE_WEB=$${SFB_REQUIRE_WEB}"; \
	fi; \
	BUILD=$(BUILD) SHAPES=$(SHAPES) CC="$(CC)" CXX="$(CXX)" JOBS=$(JOBS) ./tests/run_all.sh

# The web checks alone (tests/web/: the validator wrapper, three.js in headless Chromium against
# the software renderer): what make test runs as the suites web_validate and web_render.
test-web: deps-web $(BUILD)/surfblend $(BUILD)/web/png_iou
	BUILD=$(BUILD) ./tests/web/validate_test.sh
	BUILD=$(BUILD) SHAPES=$(SHAPES) ./tests/web/render_test.sh

# ---- install ----
# make install [PREFIX=/usr/local] [DESTDIR=]: the header and the backends/ headers it includes
# from beside itself in $(INCLUDEDIR)/surfblend/, the programs in $(BINDIR), surfblend.pc in
# $(PKGCONFIGDIR) (Cflags -I$(INCLUDEDIR)/surfblend, so that #include "surfblend.h" works as in
# examples/; Libs what the implementation needs). INSTALL_PROGRAMS are built and installed;
# INSTALL_PROGRAMS_IF_BUILT are installed when $(BUILD)/NAME exists (a program whose build rule
# is elsewhere: move it to INSTALL_PROGRAMS once this Makefile builds it).
PREFIX      ?= /usr/local
DESTDIR     ?=
BINDIR      ?= $(PREFIX)/bin
INCLUDEDIR  ?= $(PREFIX)/include
LIBDIR      ?= $(PREFIX)/lib
PKGCONFIGDIR?= $(LIBDIR)/pkgconfig
INSTALL     ?= install
INSTALL_PROGRAMS         ?= surfblend sfb2gltf
INSTALL_PROGRAMS_IF_BUILT ?=
SFB_VERSION := $(shell sed -nE 's/^\#define SFB_VERSION_(MAJOR|MINOR|PATCH) ([0-9]+).*/\2/p' src/sfb_api.h | paste -sd. -)
INSTALL_HEADERS := $(shell find backends -name '*.h' | LC_ALL=C sort)

$(BUILD)/surfblend.pc: src/sfb_api.h Makefile
	@mkdir -p $(BUILD)
	@printf '%s\n' 'prefix=$(PREFIX)' 'includedir=$(INCLUDEDIR)' '' 'Name: surfblend' \
	  'Description: single-header subdivision surfaces (C99); define SURFBLEND_IMPLEMENTATION (and SURFBLEND_ALL_BACKENDS) in one file' \
	  'Version: $(SFB_VERSION)' 'Cflags: -I$${includedir}/surfblend' 'Libs: -lm -lpthread -ldl' \
	  | sed 's|=$(PREFIX)/|=$${prefix}/|' > $@
	@echo "wrote $@ (prefix $(PREFIX))"

# (surfblend.pc depends on PREFIX: it is written again on every install)
install: $(addprefix $(BUILD)/,$(INSTALL_PROGRAMS))
	@rm -f $(BUILD)/surfblend.pc && $(MAKE) --no-print-directory $(BUILD)/surfblend.pc
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(INCLUDEDIR)/surfblend $(DESTDIR)$(PKGCONFIGDIR)
	$(INSTALL) -m 644 surfblend.h $(DESTDIR)$(INCLUDEDIR)/surfblend/surfblend.h
	@for h in $(INSTALL_HEADERS); do \
	  $(INSTALL) -d $(DESTDIR)$(INCLUDEDIR)/surfblend/$$(dirname $$h) && \
	  $(INSTALL) -m 644 $$h $(DESTDIR)$(INCLUDEDIR)/surfblend/$$h || exit 1; \
	done; echo "installed surfblend.h and $(words $(INSTALL_HEADERS)) backend headers in $(DESTDIR)$(INCLUDEDIR)/surfblend"
	@for p in $(INSTALL_PROGRAMS); do echo "$(INSTALL) -m 755 $(BUILD)/$$p $(DESTDIR)$(BINDIR)/$$p"; \
	  $(INSTALL) -m 755 $(BUILD)/$$p $(DESTDIR)$(BINDIR)/$$p || exit 1; done
	@for p in $(INSTALL_PROGRAMS_IF_BUILT); do \
	  if [ -x $(BUILD)/$$p ]; then echo "$(INSTALL) -m 755 $(BUILD)/$$p $(DESTDIR)$(BINDIR)/$$p"; \
	    $(INSTALL) -m 755 $(BUILD)/$$p $(DESTDIR)$(BINDIR)/$$p || exit 1; \
	  else echo "$$p: not built ($(BUILD)/$$p), not installed"; fi; done
	$(INSTALL) -m 644 $(BUILD)/surfblend.pc $(DESTDIR)$(PKGCONFIGDIR)/surfblend.pc

uninstall:
	rm -f $(addprefix $(DESTDIR)$(BINDIR)/,$(INSTALL_PROGRAMS) $(INSTALL_PROGRAMS_IF_BUILT)) $(DESTDIR)$(PKGCONFIGDIR)/surfblend.pc
	rm -rf $(DESTDIR)$(INCLUDEDIR)/surfblend

# The suites again under AddressSanitizer + UndefinedBehaviorSanitizer, on the reduced but
# complete profile: every suite and code path, on the peer shapes of tests/sanitize_shapes.txt
# (the large and repetitive ones run unsanitized in make test), without the checks that only
# compile (SFB_TEST_PROFILE=sanitize, tests/run_all.sh). LeakSanitizer reports inside the GL
# drivers (Mesa, LLVM) are suppressed by tests/lsan.supp, which names driver libraries only,
# never surfblend's code.
ASAN_BUILD ?= build-asan
asan:
	@rm -rf $(ASAN_BUILD)/sanitize-shapes && mkdir -p $(ASAN_BUILD)/sanitize-shapes && \
	for s in $$(grep -v '^#' tests/sanitize_shapes.txt); do \
	  [ -f "$(SHAPES)/$$s.obj" ] && ln -s "$(abspath $(SHAPES))/$$s.obj" $(ASAN_BUILD)/sanitize-shapes/; \
	done; true
	LSAN_OPTIONS="suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0$${LSAN_OPTIONS:+:$$LSAN_OPTIONS}" \
	SFB_TEST_PROFILE=sanitize \
	$(MAKE) --no-print-directory test BUILD=$(ASAN_BUILD) OPT=-O1 \
	  SHAPES=$$([ -d "$(SHAPES)" ] && echo $(ASAN_BUILD)/sanitize-shapes || echo $(SHAPES)) \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"

# The simd backend's NEON kernels against ref, on AArch64 under qemu (tests/neon.sh).
test-neon: deps-neon amalgamate-check
	BUILD=$(BUILD) SHAPES=$(SHAPES) ./tests/neon.sh

# ---- benchmark ----
$(BUILD)/bench: bench/bench.cpp tests/egl_host.h examples/fillet_shapes.h $(BUILD)/libsfb.o
	$(CXX) $(CXXFLAGS) -I. bench/bench.cpp $(BUILD)/libsfb.o -o $@ $(BENCH_LIBS) $(LIBS)

# The benchmark and the library under it built together at -O3 in a folder of their own, so the
# figures do not depend on which flags the last build of $(BUILD)/libsfb.o used (-O2 for the
# tests: tribezier's construction is 25 % slower there).
bench: deps-test
	$(MAKE) --no-print-directory BUILD=$(BUILD)/o3 OPT=-O3 $(BUILD)/o3/bench
	$(abspath $(BUILD))/o3/bench
	@$(MAKE) --no-print-directory deps-web || echo "make deps-web failed: no gltfpack column"
	$(MAKE) --no-print-directory $(BUILD)/sfb2gltf
	BUILD=$(BUILD) SHAPES=$(SHAPES) ./bench/gltf.sh

# ---- fuzzing (libFuzzer, clang) ----
FUZZ_TIME ?= 60
FUZZ_TARGETS := $(patsubst fuzz/%.c,$(BUILD)/fuzz/%,$(wildcard fuzz/fuzz_*.c))
FUZZ_CFLAGS := -std=c99 -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -I.
FUZZ_RUNS := $(patsubst fuzz/%.c,fuzz-run-%,$(wildcard fuzz/fuzz_*.c))

# the library is compiled once, instrumented for coverage (fuzzer-no-link), and every target links
# with it: seven whole-library compiles were half of the fuzz phase's time
$(BUILD)/fuzz/impl.o: surfblend.h tools/impl.c | deps-fuzz
	@mkdir -p $(BUILD)/fuzz
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -c -x c tools/impl.c -o $@

$(BUILD)/fuzz/%: fuzz/%.c $(BUILD)/fuzz/impl.o
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(BUILD)/fuzz/impl.o -o $@ $(LIBS)

# one goal per target, so that make -j2 fuzz runs two at a time
.PHONY: $(FUZZ_RUNS)
fuzz: $(FUZZ_RUNS)
$(FUZZ_RUNS): fuzz-run-%: $(BUILD)/fuzz/% | deps-fuzz
	@name=$*; t=$(BUILD)/fuzz/$$name; work=$(BUILD)/fuzz/corpus-$$name; mkdir -p $$work; \
	  ./$$t -max_total_time=$(FUZZ_TIME) -dict=fuzz/obj.dict -print_final_stats=1 -artifact_prefix=$$work- $$work fuzz/corpus > $$work.log 2>&1; rc=$$?; \
	  { echo "== $$name for $(FUZZ_TIME) s"; tail -n 12 $$work.log; }; [ $$rc -eq 0 ] || { \
	    echo "$$name FAILED (exit $$rc; log: $$work.log); the report:"; grep -m1 'Seed:' $$work.log; \
	    sed -n '/invariant violated\|==ERROR\|ERROR: libFuzzer\|runtime error\|deadly signal/,$$p' $$work.log | head -n 80; \
	    for c in $$work-crash-* $$work-leak-* $$work-timeout-* $$work-oom-*; do [ -f "$$c" ] || continue; \
	      echo "input $$c (base64; reproduce: base64 -d > in && $$t in):"; base64 -w 100 "$$c" | head -n 40; done; \
	    exit 1; }

clean:
	rm -rf build build-asan out
