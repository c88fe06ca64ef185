# pdesolid: `make` builds build/pdesolid; `make test` builds and runs every test
# (under AddressSanitizer and UndefinedBehaviorSanitizer); `make check T=test_x
# F=pattern` runs one; `make fuzz` runs the fuzzers; `make bench` runs the
# benchmarks. Dependencies point one way: clients -> api -> core.

CC      ?= cc
OPT     ?= -O3 -g
STD     := -std=c11 -D_DEFAULT_SOURCE
WARN    := -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wmissing-prototypes
CFLAGS  += $(STD) $(OPT) $(WARN) -Icore -Iapi
LDLIBS  := -lm
LIBS    := $(shell pkg-config --libs libcjson 2>/dev/null || echo -lcjson) -lnettle $(shell pkg-config --libs fftw3 2>/dev/null || echo -lfftw3) -lmeshoptimizer
CJSON_CFLAGS := $(shell pkg-config --cflags libcjson 2>/dev/null || echo -I/usr/include/cjson)
CMOCKA  := $(shell pkg-config --libs cmocka 2>/dev/null || echo -lcmocka)
SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

CORE_SRC := $(wildcard core/*.c)
API_SRC  := $(wildcard api/*.c)
CLI_SRC  := $(wildcard clients/cli/*.c)
SRV_SRC  := $(wildcard server/*.c)
TEST_SRC := $(filter-out tests/support.c,$(wildcard tests/test_*.c))
BENCH_SRC := $(filter-out bench/mhd_minimal.c,$(wildcard bench/*.c))

# Normal objects in build/obj, sanitised ones in build/san.
obj = $(patsubst %.c,build/obj/%.o,$(1))
san = $(patsubst %.c,build/san/%.o,$(1))

CORE_OBJ := $(call obj,$(CORE_SRC))
API_OBJ  := $(call obj,$(API_SRC))
CLI_OBJ  := $(call obj,$(CLI_SRC))
SRV_OBJ  := $(call obj,$(SRV_SRC))
MHD      := $(shell pkg-config --libs libmicrohttpd 2>/dev/null || echo -lmicrohttpd)
CURL     := $(shell pkg-config --libs libcurl 2>/dev/null || echo -lcurl)
# The server's durable-id stores (server/store_*.c): LMDB and hiredis, linked wherever the server is.
MHD      += -llmdb $(shell pkg-config --libs hiredis 2>/dev/null || echo -lhiredis)

TESTS := $(patsubst tests/%.c,build/san/tests/%,$(TEST_SRC))
BENCHES := $(patsubst bench/%.c,build/bench/%,$(BENCH_SRC))

# The fuzzing harnesses (tests/fuzz/, `make fuzz`) and their clang objects.
FUZZ_SECONDS ?= 60
FUZZ_CC ?= clang
FUZZ_SRC := $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_NAMES := $(patsubst tests/fuzz/%.c,%,$(FUZZ_SRC))
FUZZ_REPLAYS := $(patsubst %,build/san/fuzz/%,$(FUZZ_NAMES))
FUZZ_LIB_SRC := $(filter-out server/main.c,$(SRV_SRC)) $(API_SRC) $(CORE_SRC) tests/support.c
fuzzobj = $(patsubst %.c,build/fuzz/obj/%.o,$(1))

.PHONY: all test check fuzz bench clean deps run tsan install uninstall cluster cluster-stop
all: build/pdesolid build/pdesolidd

# Installs missing Debian and npm packages (a no-op when all are there).
deps:
	@bash .ci/deps

# Builds and starts pdesolidd on http://127.0.0.1:8080/ (ARGS="--port 9000 ..." for flags).
run: all
	build/pdesolidd $(ARGS)

# Complex division without C99's NaN and overflow recovery: the core's systems are scaled to O(1).
# Where the compiler has no such flag (clang), the C99 way, more slowly.
CX_RULES := $(shell $(CC) -fcx-fortran-rules -E -x c /dev/null >/dev/null 2>&1 && echo -fcx-fortran-rules)
build/obj/core/%.o build/san/core/%.o: CFLAGS += $(CX_RULES)

build/obj/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(CJSON_CFLAGS) -MMD -MP -c $< -o $@

build/san/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(CJSON_CFLAGS) $(SAN) -MMD -MP -c $< -o $@

build/libpdecore.a: $(CORE_OBJ)
	$(AR) rcs $@ $^

build/libpdeapi.a: $(API_OBJ)
	$(AR) rcs $@ $^

build/pdesolid: $(CLI_OBJ) build/libpdeapi.a build/libpdecore.a
	$(CC) $(CFLAGS) $^ $(LIBS) $(CURL) $(LDLIBS) -o $@

# docs/openapi.yaml, linked into the daemon, which serves it at /openapi.yaml.
build/obj/openapi.o: docs/openapi.yaml
	@mkdir -p $(dir $@)
	ld -r -b binary -z noexecstack -o $@ $<

build/pdesolidd: $(SRV_OBJ) build/obj/openapi.o build/libpdeapi.a build/libpdecore.a
	$(CC) $(CFLAGS) $^ $(LIBS) $(MHD) $(LDLIBS) -lpthread -o $@

# The sanitised daemon, which the integration tests start.
build/san/pdesolidd: $(call san,$(SRV_SRC) $(API_SRC) $(CORE_SRC)) build/obj/openapi.o
	$(CC) $(CFLAGS) $(SAN) $^ $(LIBS) $(MHD) $(LDLIBS) -lpthread -o $@

# The sanitised CLI, which the CLI tests drive alongside build/pdesolid.
build/san/pdesolid: $(call san,$(CLI_SRC) $(API_SRC) $(CORE_SRC))
	$(CC) $(CFLAGS) $(SAN) $^ $(LIBS) $(CURL) $(LDLIBS) -o $@

# Tests link the server's modules too (all but main.c), for test_config and test_log.
build/san/tests/%.o: CFLAGS += -Iserver
build/san/tests/%: build/san/tests/%.o build/san/tests/support.o $(call san,$(filter-out server/main.c,$(SRV_SRC)) \
                   $(API_SRC) $(CORE_SRC)) build/obj/openapi.o
	$(CC) $(CFLAGS) $(SAN) $^ $(LIBS) $(CMOCKA) $(CURL) $(MHD) $(LDLIBS) -lpthread -o $@

# test_errors fails allocations on purpose: malloc, calloc and realloc wrapped at link time.
build/san/tests/test_errors: LDLIBS += -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc

# Test binaries that start pdesolidd, or run the CLI, need them built first (order-only: a new
# daemon does not relink the test). Found by what the tests read, so a new test needs no entry here.
DAEMON_TESTS := $(patsubst tests/%.c,build/san/tests/%,$(shell grep -l 'daemon_start\|PDESOLIDD_SAN' $(TEST_SRC)))
CLI_TESTS := $(patsubst tests/%.c,build/san/tests/%,$(shell grep -l 'PDESOLID_SAN\|getenv("PDESOLID")' $(TEST_SRC)))
$(DAEMON_TESTS): | build/san/pdesolidd
$(CLI_TESTS): | build/pdesolid build/san/pdesolid
TEST_ENV := PDESOLID=build/pdesolid PDESOLID_SAN=build/san/pdesolid PDESOLIDD_SAN=build/san/pdesolidd

# Keep every intermediate (test objects above all), so that a second `make test` rebuilds nothing.
.SECONDARY:

test: build/pdesolid build/pdesolidd build/san/pdesolid build/san/pdesolidd $(TESTS) $(FUZZ_REPLAYS)
	@set -e; for t in $(TESTS); do echo "== $$t"; $(TEST_ENV) ./$$t; done
	@set -e; for f in $(FUZZ_NAMES); do echo "== build/san/fuzz/$$f (seed corpus replay)"; \
	    ./build/san/fuzz/$$f tests/fuzz/corpus/$$f; done

# One test program, and optionally only its cases matching a cmocka pattern:
# `make check T=test_solve`, `make check T=test_solve F='*resonan*'`.
check: $(if $(T),build/san/tests/$(T))
	@test -n "$(T)" || { echo "make check T=test_name [F='pattern']" >&2; exit 2; }
	$(TEST_ENV) CMOCKA_FILTER='$(F)' ./build/san/tests/$(T)

# ---- fuzzing: libFuzzer harnesses (tests/fuzz/fuzz_*.c, seed corpora in tests/fuzz/corpus/<name>/) ----
# `make fuzz` builds them with clang into build/fuzz/ and runs each for FUZZ_SECONDS over its corpus;
# new inputs go to build/fuzz/corpus-<name>/, a crash fails the target and leaves its input in
# build/fuzz/<name>-crash-*. `make test` replays the seed corpora through the same harnesses built
# with $(CC) and tests/fuzz/replay.c instead of libFuzzer (build/san/fuzz/<name>).

# clang has no -fcx-fortran-rules: its core objects divide complex numbers the C99 way, more slowly.
build/fuzz/obj/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(STD) $(OPT) $(WARN) -Icore -Iapi -Iserver -Itests $(CJSON_CFLAGS) $(SAN) \
	    -fsanitize=fuzzer-no-link -MMD -MP -c $< -o $@

build/fuzz/fuzz_%: build/fuzz/obj/tests/fuzz/fuzz_%.o $(call fuzzobj,$(FUZZ_LIB_SRC)) build/obj/openapi.o
	$(FUZZ_CC) $(SAN) -fsanitize=fuzzer $^ $(LIBS) $(CMOCKA) $(CURL) $(MHD) $(LDLIBS) -lpthread -o $@

build/san/tests/fuzz/%.o: CFLAGS += -Itests
build/san/fuzz/fuzz_%: build/san/tests/fuzz/fuzz_%.o build/san/tests/fuzz/replay.o \
                       $(call san,$(FUZZ_LIB_SRC)) build/obj/openapi.o
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SAN) $^ $(LIBS) $(CMOCKA) $(CURL) $(MHD) $(LDLIBS) -lpthread -o $@

fuzz: $(patsubst %,build/fuzz/%,$(FUZZ_NAMES))
	@set -e; for f in $(FUZZ_NAMES); do mkdir -p build/fuzz/corpus-$$f; \
	    echo "== build/fuzz/$$f for $(FUZZ_SECONDS) s"; \
	    ./build/fuzz/$$f -max_total_time=$(FUZZ_SECONDS) -timeout=10 -max_len=4096 -print_final_stats=1 \
	        -dict=tests/fuzz/$$f.dict -artifact_prefix=build/fuzz/$$f- build/fuzz/corpus-$$f tests/fuzz/corpus/$$f; \
	done

# The server's integration tests against a ThreadSanitizer build of pdesolidd; a race
# leaves a report in build/tsan/ and fails the target.
build/tsan/pdesolidd: $(SRV_SRC) $(API_SRC) $(CORE_SRC) build/obj/openapi.o
	@mkdir -p $(dir $@)
	$(CC) $(STD) -O1 -g $(WARN) -Icore -Iapi $(CJSON_CFLAGS) -fcx-fortran-rules -fsanitize=thread $^ \
	    $(LIBS) $(MHD) $(LDLIBS) -lpthread -o $@

TSAN_TESTS := test_server test_hostile test_store

tsan: build/tsan/pdesolidd $(TSAN_TESTS:%=build/san/tests/%) build/pdesolid build/san/pdesolid
	@rm -f build/tsan/report.*
	@set -e; for t in $(TSAN_TESTS); do PDESOLIDD_SAN=build/tsan/pdesolidd PDESOLID=build/pdesolid \
	    PDESOLID_SAN=build/san/pdesolid TSAN_OPTIONS="log_path=$(CURDIR)/build/tsan/report" ./build/san/tests/$$t; done
	@if ls build/tsan/report.* >/dev/null 2>&1; then cat build/tsan/report.*; exit 1; fi

build/bench/%: bench/%.c build/libpdeapi.a build/libpdecore.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(CJSON_CFLAGS) $^ $(LIBS) $(LDLIBS) -o $@

build/bench/bench_log: bench/bench_log.c build/obj/server/log.o build/libpdeapi.a build/libpdecore.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Iserver $^ $(LIBS) $(LDLIBS) -lpthread -o $@

build/bench/bench_store: bench/bench_store.c $(call obj,server/store.c server/store_lmdb.c server/store_redis.c server/sbuf.c) \
	    build/libpdeapi.a build/libpdecore.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Iserver $^ $(LIBS) $(MHD) $(LDLIBS) -lpthread -o $@

# bench_cost measures the heap's peak by wrapping malloc.
build/bench/bench_cost: LDLIBS += -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free

build/bench/mhd_minimal: bench/mhd_minimal.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(MHD) -lpthread -o $@

bench: $(BENCHES) build/pdesolidd build/bench/mhd_minimal
	@for b in $(BENCHES); do ./$$b; done
	@bash bench/bench_server.sh
	@bash bench/bench_livez.sh
	@bash bench/bench_413.sh
	@bash bench/bench_shutdown.sh
	@bash bench/bench_props_latency.sh
	@bash bench/bench_cluster.sh

clean:
	rm -rf build

# ---- A cluster on this machine (deploy/cluster.sh): Redis, three replicas, nginx on 127.0.0.1:8088
# (CLUSTER_PORT=N to change); state, logs and pid files in build/cluster/ (CLUSTER_DIR=DIR). The
# replicas run CLUSTER_DAEMON: build/pdesolidd, or build/san/pdesolidd (tests/test_cluster.c).
# `make cluster` again restarts whatever died; `make cluster-stop` ends it.
CLUSTER_DAEMON ?= build/pdesolidd
CLUSTER_ENV = CLUSTER_PORT=$(or $(CLUSTER_PORT),8088) CLUSTER_DIR=$(or $(CLUSTER_DIR),build/cluster) \
              CLUSTER_REPLICAS=$(or $(CLUSTER_REPLICAS),3) PDESOLIDD=$(CLUSTER_DAEMON)
cluster: $(CLUSTER_DAEMON)
	@$(CLUSTER_ENV) bash deploy/cluster.sh start

cluster-stop:
	@$(CLUSTER_ENV) bash deploy/cluster.sh stop

# ---- `make install [PREFIX=/usr/local] [DESTDIR=]`: the programs, the front-end, the manual pages and
# the systemd unit (deploy/README.md). The front-end's files are the file column of server/static.c's
# table, so a file the daemon serves is a file that is installed.
PREFIX ?= /usr/local
BINDIR ?= $(PREFIX)/bin
SBINDIR ?= $(PREFIX)/sbin
DATADIR ?= $(PREFIX)/share/pdesolid
MANDIR ?= $(PREFIX)/share/man
UNITDIR ?= $(PREFIX)/lib/systemd/system
WEB_FILES := $(shell grep -o '"[^/"][^"]*\.\(html\|js\|css\)"' server/static.c | tr -d '"' | sort -u)

install: all
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(SBINDIR) $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(MANDIR)/man8 \
	    $(DESTDIR)$(UNITDIR)
	install -m 0755 build/pdesolid $(DESTDIR)$(BINDIR)/pdesolid
	install -m 0755 build/pdesolidd $(DESTDIR)$(SBINDIR)/pdesolidd
	install -m 0644 deploy/pdesolid.1 $(DESTDIR)$(MANDIR)/man1/pdesolid.1
	install -m 0644 deploy/pdesolidd.8 $(DESTDIR)$(MANDIR)/man8/pdesolidd.8
	sed -e 's|@SBINDIR@|$(SBINDIR)|g' -e 's|@DATADIR@|$(DATADIR)|g' deploy/pdesolidd.service \
	    > $(DESTDIR)$(UNITDIR)/pdesolidd.service
	chmod 0644 $(DESTDIR)$(UNITDIR)/pdesolidd.service
	@set -e; for f in $(WEB_FILES); do install -D -m 0644 clients/web/$$f $(DESTDIR)$(DATADIR)/web/$$f; done

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/pdesolid $(DESTDIR)$(SBINDIR)/pdesolidd $(DESTDIR)$(MANDIR)/man1/pdesolid.1 \
	    $(DESTDIR)$(MANDIR)/man8/pdesolidd.8 $(DESTDIR)$(UNITDIR)/pdesolidd.service
	rm -rf $(DESTDIR)$(DATADIR)

-include $(shell find build -name '*.d' 2>/dev/null)
