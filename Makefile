# rtsh — a ray tracer and command shell that lives in the terminal.
#
#   make            build ./rtsh
#   make run        build and open the shell on the built-in showcase scene
#   make test       build and run every test, then again under ASan+UBSan, and
#                   the threaded tests under TSan
#   make bench      build and run the benchmark (writes build/bench.tsv), the
#                   rtsh-mpi rows (build/bench-mpi.tsv, when mpirun exists), then
#                   bench-quality: rtsh against Cycles at equal noise (skipped
#                   without blender) and the preview's time to an error
#   make mpi        build ./rtsh-mpi, the Open MPI renderer (`make` builds it
#                   too when mpicc is installed)
#   make fuzz       build the libFuzzer targets (clang) and run each for
#                   FUZZ_SECONDS (default 60) on tests/fuzz/corpus
#   make install    PREFIX=/usr/local DESTDIR=  (binary, man pages, scenes)
#
# Variants build in their own folder: `make BUILD=build/asan SAN=address,undefined`.

PREFIX  ?= /usr/local
DESTDIR ?=
BUILD   ?= build
SAN     ?=
OPT     ?= -O2

CC      ?= cc
VERSION := 0.1.0
CSTD    := -std=c17
WARN    := -Wall -Wextra -Wpedantic -Werror -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wvla
CPPFLAGS += -Iinclude -Isrc -I$(BUILD) -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -DRTSH_VERSION=\"$(VERSION)\"
CFLAGS  ?= $(OPT) -g
CFLAGS  += $(CSTD) $(WARN) -fno-math-errno -pthread -MMD -MP
# assimp, libXpm and cJSON are opened when a model, an XPM image or a glTF
# first needs them (src/base/dynlib.h): not linked, so that no other start-up
# maps them (with libstdc++ and five X11 libraries). Their headers are still
# needed to build.
LDLIBS_CORE := -lpng -lstb -lm -pthread
# libsixel is opened on the first sixel picture (src/term/enc_sixel.c, dlopen), not linked.
LDLIBS_FRONT := -lreadline -lncursesw $(LDLIBS_CORE) -lz

ifneq ($(SAN),)
CFLAGS  += -fsanitize=$(SAN) -fno-omit-frame-pointer -fno-sanitize-recover=all
LDFLAGS += -fsanitize=$(SAN)
endif

CORE_SRC  := $(sort $(wildcard src/base/*.c src/model/*.c src/core/*.c src/core/*/*.c src/scene/*.c))
FRONT_SRC := $(sort $(wildcard src/term/*.c src/shell/*.c))
CORE_OBJ  := $(CORE_SRC:%.c=$(BUILD)/%.o)
FRONT_OBJ := $(FRONT_SRC:%.c=$(BUILD)/%.o)
MAIN_OBJ  := $(BUILD)/src/main.o
LIB       := $(BUILD)/librtsh.a
FRONTLIB  := $(BUILD)/librtsh-front.a

TEST_SRC  := $(sort $(wildcard tests/unit/test_*.c))
TEST_BIN  := $(TEST_SRC:tests/unit/%.c=$(BUILD)/tests/%)
EXAMPLE_BIN := $(patsubst examples/%.c,$(BUILD)/examples/%,$(sort $(wildcard examples/*.c)))
# The link simulator (tests/link): a program on a pty behind a slow wire.
LINKSIM   := $(BUILD)/tests/linksim
BENCH_SRC := bench/bench.c
BENCH_BIN := $(BUILD)/bench/bench
# Optional: Embree 3's single-ray speed on the same rays, built by `make bench`
# only when embree3/rtcore.h is installed (apt-get install libembree-dev).
EMBREE_BIN := $(BUILD)/bench/embree_primary
EMBREE_MESH_BIN := $(BUILD)/bench/embree_mesh
EMBREE_BUILD_BIN := $(BUILD)/bench/embree_build
# Equal-quality rows (rtsh against Blender's Cycles, preview time to an
# error): bench/quality.c, run by `make bench` after the speed table.
QUALITY_BIN := $(BUILD)/bench/quality

# The binary: ./rtsh for the default build, $(BUILD)/rtsh for variants.
ifeq ($(BUILD),build)
BIN := rtsh
else
BIN := $(BUILD)/rtsh
endif

# rtsh-mpi: only its own objects are compiled with mpicc; rtsh never links MPI.
MPICC    ?= mpicc
MPI_SRC  := $(sort $(wildcard src/mpi/*.c))
MPI_OBJ  := $(MPI_SRC:%.c=$(BUILD)/%.o)
MPI_BIN  := $(patsubst %rtsh,%rtsh-mpi,$(BIN))
HAVE_MPI := $(shell command -v $(MPICC) 2>/dev/null)

.PHONY: all run test test-bins test-unit test-scripts bench bench-quick bench-quality install uninstall \
        clean deps check-man fuzz fuzz-bins fuzz-link mpi

all: deps $(BIN) $(if $(HAVE_MPI),$(MPI_BIN))

mpi: deps $(MPI_BIN)

$(MPI_BIN): $(MPI_OBJ) $(FRONTLIB) $(LIB)
	@echo "  LD      $@"
	@$(MPICC) $(LDFLAGS) -o $@ $^ $(LDLIBS_CORE)

$(BUILD)/src/mpi/%.o: src/mpi/%.c
	@mkdir -p $(@D)
	@echo "  MPICC   $<"
	@$(MPICC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

deps:
	@sh tests/deps.sh

$(BIN): $(MAIN_OBJ) $(FRONTLIB) $(LIB)
	@echo "  LD      $@"
	@$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS_FRONT)

$(LIB): $(CORE_OBJ)
	@mkdir -p $(@D)
	@echo "  AR      $@"
	@rm -f $@ && $(AR) rcs $@ $^

$(FRONTLIB): $(FRONT_OBJ)
	@mkdir -p $(@D)
	@echo "  AR      $@"
	@rm -f $@ && $(AR) rcs $@ $^

$(BUILD)/%.o: %.c
	@mkdir -p $(@D)
	@echo "  CC      $<"
	@$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

# The triangle walk is built with clang where it is installed and the build
# is not sanitized (a sanitized build keeps one compiler's runtime): clang
# schedules the walk's loops better than GCC 12 (diffuse rays +4-6%,
# bench/README.md). The same floats either way: no fused multiply-adds
# (-ffp-contract=off, GCC's default under -std=c17). WALK_CC=cc builds it
# like the rest.
ifeq ($(origin WALK_CC),undefined)
ifeq ($(SAN),)
WALK_CC := $(shell command -v clang >/dev/null 2>&1 && echo clang || echo $(CC))
else
WALK_CC := $(CC)
endif
endif
$(BUILD)/src/core/mesh/mesh_trace.o: src/core/mesh/mesh_trace.c
	@mkdir -p $(@D)
	@echo "  CC      $< ($(WALK_CC))"
	@$(WALK_CC) $(CPPFLAGS) $(CFLAGS) -ffp-contract=off -c -o $@ $<

# The built-in showcase scene, compiled in so `rtsh` works from any folder.
$(BUILD)/src/shell/builtin_scene.o: $(BUILD)/gen/showcase.inc
$(BUILD)/gen/showcase.inc: scenes/showcase.rt
	@mkdir -p $(@D)
	sh tests/embed.sh $< > $@

$(BUILD)/tests/%: tests/unit/%.c $(FRONTLIB) $(LIB)
	@mkdir -p $(@D)
	@echo "  TEST    $@"
	@$(CC) $(CPPFLAGS) -Itests/unit $(CFLAGS) $(LDFLAGS) -o $@ $< $(FRONTLIB) $(LIB) -lcmocka $(LDLIBS_FRONT)

# rtsh-mpi's configuration encoder holds no MPI: its test links it alone.
$(BUILD)/tests/test_mpi_wire: tests/unit/test_mpi_wire.c src/mpi/wire.c $(FRONTLIB) $(LIB)
	@mkdir -p $(@D)
	@echo "  TEST    $@"
	@$(CC) $(CPPFLAGS) -Itests/unit $(CFLAGS) $(LDFLAGS) -o $@ $< src/mpi/wire.c $(FRONTLIB) $(LIB) \
		-lcmocka $(LDLIBS_FRONT)

$(BENCH_BIN): $(BENCH_SRC) $(FRONTLIB) $(LIB)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $< $(FRONTLIB) $(LIB) $(LDLIBS_FRONT)

run: all
	./$(BIN)

test-bins: $(TEST_BIN) $(LINKSIM) $(EXAMPLE_BIN)

# The embedding example: the public header (include/rtsh/rtsh.h) and
# librtsh.a only, no -Isrc; tests/scripts/example.test runs it.
$(BUILD)/examples/%: examples/%.c $(LIB)
	@mkdir -p $(@D)
	@echo "  CC      $@"
	@$(CC) -Iinclude $(CFLAGS) $(LDFLAGS) -o $@ $< $(LIB) $(LDLIBS_CORE)

$(LINKSIM): tests/link/linksim.c
	@mkdir -p $(@D)
	@echo "  CC      $@"
	@$(CC) $(CFLAGS) $(LDFLAGS) -o $@ $< -lutil

# The whole suite: plain build, tmux end to end, then ASan+UBSan, then TSan on
# the threaded tests; the last line is "N passed, N failed".
test: deps
	@sh tests/run-all.sh

test-unit: $(BIN) $(TEST_BIN)
	@sh tests/run-unit.sh $(BUILD) $(TEST_BIN)

test-scripts: $(BIN)
	@sh tests/run-scripts.sh ./$(BIN)

$(EMBREE_BIN): bench/embree_primary.c bench/embree_packets.h $(LIB)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $< $(LIB) -lembree3 $(LDLIBS_CORE)

$(EMBREE_MESH_BIN): bench/embree_mesh.c bench/mesh_rays.h bench/embree_packets.h $(LIB)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $< $(LIB) -lembree3 $(LDLIBS_CORE)

$(EMBREE_BUILD_BIN): bench/embree_build.c $(LIB)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $< $(LIB) -lembree3 $(LDLIBS_CORE)

bench: all $(BENCH_BIN)
	@if printf '#include <embree3/rtcore.h>\n' | $(CC) -E -x c - >/dev/null 2>&1; then \
		$(MAKE) --no-print-directory $(EMBREE_BIN) $(EMBREE_MESH_BIN) $(EMBREE_BUILD_BIN); \
	else echo "bench: no embree3/rtcore.h, so no Embree row (apt-get install libembree-dev)"; fi
	./$(BENCH_BIN) --out $(BUILD)/bench.tsv
	@sh bench/mpi.sh --out $(BUILD)/bench-mpi.tsv
	$(MAKE) --no-print-directory bench-quality

# rtsh against Cycles (skipped with a message without `blender`) and the
# preview's time to an error; references are rendered once into
# $(BUILD)/quality/ (minutes the first time).
bench-quality: all $(QUALITY_BIN)
	./$(QUALITY_BIN) --out $(BUILD)/bench-quality.tsv

$(QUALITY_BIN): bench/quality.c $(LIB)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $< $(LIB) $(LDLIBS_CORE)

bench-quick: all $(BENCH_BIN)
	./$(BENCH_BIN) --quick --out $(BUILD)/bench-quick.tsv
	@sh bench/mpi.sh --quick --out $(BUILD)/bench-mpi-quick.tsv

# libFuzzer targets (tests/fuzz/fuzz_NAME.c), built with clang under
# ASan+UBSan in build/fuzz; `make fuzz` runs each for FUZZ_SECONDS.
FUZZ_SRC     := $(sort $(wildcard tests/fuzz/fuzz_*.c))
FUZZ_BIN     := $(FUZZ_SRC:tests/fuzz/%.c=$(BUILD)/%)
FUZZ_SECONDS ?= 60

fuzz-bins:
	@$(MAKE) --no-print-directory -s BUILD=build/fuzz CC=clang OPT=-O1 \
		SAN=fuzzer-no-link,address,undefined fuzz-link

fuzz-link: $(FUZZ_BIN)

$(BUILD)/fuzz_%: tests/fuzz/fuzz_%.c $(FRONTLIB) $(LIB)
	@mkdir -p $(@D)
	@echo "  FUZZ    $@"
	@$(CC) $(CPPFLAGS) $(CFLAGS) -fsanitize=fuzzer,address,undefined -o $@ $< $(FRONTLIB) $(LIB) \
		$(LDLIBS_FRONT)

fuzz: deps fuzz-bins
	@sh tests/fuzz/run.sh build/fuzz $(FUZZ_SECONDS)

check-man:
	@for m in man/rtsh.1 man/rtsh.5 man/rtsh-mpi.1; do \
		out=$$(LC_ALL=C.UTF-8 MANWIDTH=80 groff -man -ww -z $$m 2>&1); \
		if [ -n "$$out" ]; then echo "$$m: $$out"; exit 1; fi; \
		if command -v mandoc >/dev/null 2>&1; then out=$$(mandoc -Tlint -W style $$m 2>&1); if [ -n "$$out" ]; then echo "$$out"; exit 1; fi; fi; \
	done; echo "man pages clean"

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/share/man/man1 \
		$(DESTDIR)$(PREFIX)/share/man/man5 $(DESTDIR)$(PREFIX)/share/rtsh/scenes
	install -m 755 $(BIN) $(DESTDIR)$(PREFIX)/bin/rtsh
	if [ -x $(MPI_BIN) ]; then install -m 755 $(MPI_BIN) $(DESTDIR)$(PREFIX)/bin/rtsh-mpi; \
		install -m 644 man/rtsh-mpi.1 $(DESTDIR)$(PREFIX)/share/man/man1/rtsh-mpi.1; fi
	install -m 644 man/rtsh.1 $(DESTDIR)$(PREFIX)/share/man/man1/rtsh.1
	install -m 644 man/rtsh.5 $(DESTDIR)$(PREFIX)/share/man/man5/rtsh.5
	install -m 644 scenes/*.rt $(DESTDIR)$(PREFIX)/share/rtsh/scenes/
	# the models and textures the scenes name by relative path (spot.rt, earth.rt, fence.rt)
	for d in $$(cd scenes && find models textures -type d); do \
		install -d $(DESTDIR)$(PREFIX)/share/rtsh/scenes/$$d; done
	for f in $$(cd scenes && find models textures -type f ! -name '*.py'); do \
		install -m 644 scenes/$$f $(DESTDIR)$(PREFIX)/share/rtsh/scenes/$$f; done

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/rtsh $(DESTDIR)$(PREFIX)/share/man/man1/rtsh.1 \
		$(DESTDIR)$(PREFIX)/bin/rtsh-mpi $(DESTDIR)$(PREFIX)/share/man/man1/rtsh-mpi.1 \
		$(DESTDIR)$(PREFIX)/share/man/man5/rtsh.5
	rm -rf $(DESTDIR)$(PREFIX)/share/rtsh

clean:
	rm -rf build rtsh rtsh-mpi

-include $(CORE_OBJ:.o=.d) $(FRONT_OBJ:.o=.d) $(MAIN_OBJ:.o=.d) $(MPI_OBJ:.o=.d)
