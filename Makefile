# pointing-model library: top-level build.
#   make            build/libpm.a, build/libpm.so, build/libpmhost.a, build/pmfit
#   make test       build and run the Check suites (ends with Check's summary line)
#   make check-freestanding   prove the core links against nothing but libm + mem*
#   make install PREFIX=/usr/local
CC       ?= gcc
CXX      ?= g++
AR       ?= ar
PREFIX   ?= /usr/local
PYTHON   ?= /usr/bin/python3
B        := build

WARN     := -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion
OPT      ?= -O2
# The freestanding core: no exceptions, RTTI, thread-safe statics or hosted library.
# -ffreestanding turns the builtins off; -fbuiltin -fno-math-errno give them back for speed.
CORE_FLAGS := -std=c++11 $(OPT) -g $(WARN) -ffreestanding -fno-exceptions -fno-rtti \
              -fno-threadsafe-statics -fno-asynchronous-unwind-tables -fbuiltin -fno-math-errno \
              -fPIC -Iinclude
HOST_CXXFLAGS := -std=c++17 $(OPT) -g $(WARN) -pthread -Iinclude -Itools/lib
TEST_CFLAGS   := -std=c99 $(OPT) -g -Wall -Wextra -Iinclude -Itools/lib
TEST_LIBS     := $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lrt -lpthread) \
                 -llapacke -llapack -lblas -lerfa -lstdc++ -lm

CORE_SRC  := $(wildcard lib/*.cpp)
CORE_OBJ  := $(CORE_SRC:lib/%.cpp=$(B)/core/%.o)
HOST_SRC  := $(wildcard tools/lib/*.cpp)
HOST_OBJ  := $(HOST_SRC:tools/lib/%.cpp=$(B)/host/%.o)
TOOL_SRC  := $(wildcard tools/*.cpp)
TOOLS     := $(TOOL_SRC:tools/%.cpp=$(B)/%)
TEST_SRC  := $(wildcard tests/check_*.c)
TESTS     := $(TEST_SRC:tests/%.c=$(B)/tests/%)

.PHONY: sanitize sanitize-run all test test-run demo-run deps check-freestanding check-c89 check-example check-install install clean bench firmware demo
all: $(B)/libpm.a $(B)/libpm.so $(B)/libpmhost.a $(TOOLS)

$(B)/core/%.o: lib/%.cpp $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(CXX) $(CORE_FLAGS) -c $< -o $@

$(B)/libpm.a: $(CORE_OBJ)
	@rm -f $@
	$(AR) rcs $@ $^

$(B)/libpm.so: $(CORE_OBJ)
	$(CXX) -shared -nostdlib -o $@ $^ -lm -lc

$(B)/host/%.o: tools/lib/%.cpp $(wildcard include/*.h tools/lib/*.hpp tools/lib/*.h)
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -c $< -o $@

$(B)/libpmhost.a: $(HOST_OBJ)
	@rm -f $@
	$(AR) rcs $@ $^

$(B)/%: tools/%.cpp $(B)/libpmhost.a $(B)/libpm.a
	$(CXX) $(HOST_CXXFLAGS) $< -o $@ $(B)/libpmhost.a $(B)/libpm.a -lerfa -lm

$(B)/tests/%: tests/%.c $(B)/libpmhost.a $(B)/libpm.a $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(B)/libpmhost.a $(B)/libpm.a $(TEST_LIBS)

# check_bounded counts model evaluations: the core built again with a probe
# (tests/probe.h; the library itself has none).
PROBE_OBJ := $(CORE_SRC:lib/%.cpp=$(B)/probe/%.o)
$(B)/probe/%.o: lib/%.cpp tests/probe.h $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(CXX) $(CORE_FLAGS) -include tests/probe.h '-DPM_EVAL_PROBE()=pm_probe_hit()' -c $< -o $@

$(B)/tests/check_bounded $(B)/tests/check_track: $(B)/tests/%: tests/%.c $(PROBE_OBJ) $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(PROBE_OBJ) $(TEST_LIBS)

# check_model also calls PM_CHECK_CONFIG() as compiled with other capacity
# macros (tests/config_other.c: PM_MAX_AUX 1 and 8), against this library.
CONFIG_OTHER := $(B)/tests/config_aux1.o $(B)/tests/config_aux8.o
$(B)/tests/config_aux%.o: tests/config_other.c include/pm.h
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) -DPM_MAX_AUX=$* -DCONFIG_FN=pm_test_config_aux$* -c $< -o $@

$(B)/tests/check_model: tests/check_model.c $(CONFIG_OTHER) $(B)/libpmhost.a $(B)/libpm.a $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(CONFIG_OTHER) $(B)/libpmhost.a $(B)/libpm.a $(TEST_LIBS)

# check_capacity: the core built again with capacities beyond the default
# (two-digit term indices), the suite compiled with the same.
BIG_CAP := -DPM_MAX_L=10 -DPM_MAX_AUX=12
BIG_OBJ := $(CORE_SRC:lib/%.cpp=$(B)/big/%.o)
$(B)/big/%.o: lib/%.cpp $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(CXX) $(CORE_FLAGS) $(BIG_CAP) -c $< -o $@

$(B)/tests/check_capacity: tests/check_capacity.c $(BIG_OBJ) $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $(BIG_CAP) $< -o $@ $(BIG_OBJ) $(TEST_LIBS)

# check_internal tests the core's own helpers (lib/pm_detail.hpp) through a
# test-only shim compiled with the core's flags.
$(B)/tests/internal_shim.o: tests/internal_shim.cpp $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(CXX) $(CORE_FLAGS) -c $< -o $@

$(B)/tests/check_internal: tests/check_internal.c $(B)/tests/internal_shim.o $(B)/libpm.a $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(B)/tests/internal_shim.o $(B)/libpm.a $(TEST_LIBS)

# The public header must be strict ANSI C.
check-c89: include/pm.h
	@mkdir -p $(B)
	printf '#include "pm.h"\nint main(void){pm_model m; (void)m; return 0;}\n' > $(B)/c89.c
	gcc -std=c89 -pedantic -Werror -Wall -Wextra -Iinclude -c $(B)/c89.c -o $(B)/c89.o
	@echo "check-c89: include/pm.h is clean C89"

# Only libm functions and memcpy/memset may be undefined in the core.
FREESTANDING_OK := ^(sin|cos|sincos|tan|asin|acos|atan|atan2|sqrt|fabs|floor|ceil|fmod|hypot|exp|log|pow|copysign|round|trunc|remainder|nearbyint)f?$$|^mem(cpy|set|move)$$
# (Symbols one object of the core takes from another are not external.)
check-freestanding: $(B)/libpm.a
	@nm --defined-only $(B)/libpm.a | awk 'NF==3{print $$3}' | sort -u > $(B)/core.defined; \
	nm -u $(B)/libpm.a | awk 'NF==2{print $$2}' | sort -u | comm -23 - $(B)/core.defined > $(B)/core.undefined; \
	bad=$$(grep -Ev '$(FREESTANDING_OK)' $(B)/core.undefined); \
	if [ -n "$$bad" ]; then echo "check-freestanding: FAIL, the core needs:"; echo "$$bad"; exit 1; fi; \
	echo "check-freestanding: OK (external symbols: $$(tr '\n' ' ' < $(B)/core.undefined))"

# The README's commands install missing Debian packages first (tools/deps.sh).
deps:
	@sh tools/deps.sh

test: deps
	@$(MAKE) --no-print-directory test-run

# The README's main job: fit the bundled example run at L=0,1,2 and, when
# ../shared/data is there, the real recorded runs.
DATA ?= ../shared/data
demo: deps
	@$(MAKE) --no-print-directory demo-run

demo-run: all
	@echo "== bundled example: a simulated German equatorial mount (examples/sim_gem.dat)"
	$(B)/pmfit fit examples/sim_gem.dat --order 1 --residuals $(B)/sim_gem.res --save $(B)/sim_gem.pm
	@echo; echo "== what did the model leave out? (plots in $(B)/sim_gem_plots)"
	$(B)/pmfit explain examples/sim_gem.dat --plots $(B)/sim_gem_plots
	@echo; echo "== one page with all of it: $(B)/sim_gem_report.html (docs/report.md)"
	$(B)/pmfit report examples/sim_gem.dat -o $(B)/sim_gem_report.html
	@if [ -d $(DATA) ]; then \
	  echo "== real runs in $(DATA)"; \
	  $(B)/pmfit fit $(DATA)/mmt/k_and_e.dat --order 1; \
	  for f in mmt/k_and_e.dat celestial/gem-28.dat celestial/cgx-l-data.dat; do for L in 0 1 2; do \
	    printf '%s order %s: ' $$f $$L; $(B)/pmfit fit $(DATA)/$$f --order $$L --json 2>&1 | \
	    sed -E 's/.*"n_params": ([0-9]+).*"sigma_arcsec": ([0-9.]+).*/P = \1, sigma = \2 arcsec/'; \
	  done; done; \
	else echo "(no $(DATA): the real recorded runs are skipped)"; fi
	@$(MAKE) --no-print-directory python-demo
	@echo; $(MAKE) --no-print-directory indi-demo

# The README's C example, compiled as strict C89 and run on a synthetic run.
check-example: $(B)/libpm.a
	@mkdir -p $(B)
	$(CC) -std=c89 -pedantic -Werror -Wall -Wextra -Iinclude -c examples/fit_and_apply.c -o $(B)/fit_and_apply.o
	$(CC) -std=c99 -Iinclude examples/fit_and_apply_main.c $(B)/fit_and_apply.o $(B)/libpm.a -lm -o $(B)/fit_and_apply
	$(B)/fit_and_apply > $(B)/fit_and_apply.out
	@echo "check-example: README example builds as C89 and runs"

# make install into a staging directory, then build the example against the
# installed header and library through pkg-config.
check-install: all
	@rm -rf $(B)/stage
	@$(MAKE) --no-print-directory install PREFIX=$(CURDIR)/$(B)/stage > /dev/null
	$(CC) -std=c89 -pedantic -Werror -c examples/fit_and_apply.c -o $(B)/stage/fa.o \
	  $$(PKG_CONFIG_PATH=$(B)/stage/lib/pkgconfig pkg-config --cflags pm)
	$(CC) -std=c99 -c examples/fit_and_apply_main.c -o $(B)/stage/fam.o \
	  $$(PKG_CONFIG_PATH=$(B)/stage/lib/pkgconfig pkg-config --cflags pm)
	$(CC) $(B)/stage/fa.o $(B)/stage/fam.o -o $(B)/stage/fa -static-libgcc \
	  $$(PKG_CONFIG_PATH=$(B)/stage/lib/pkgconfig pkg-config --libs pm) -Wl,-rpath,$(CURDIR)/$(B)/stage/lib
	$(B)/stage/fa > /dev/null
	@echo "check-install: installed header, libraries and pm.pc build and run the example"

# Run the Check suites $(1) (a list of test programs) with the environment
# they expect, print each suite's result and one summary in Check's format;
# fail if any suite failed.
define run_suites
	@fail=0; total_run=0; total_fail=0; \
	for t in $(1); do \
	  out=$$(PM_DATA_DIR=$(CURDIR)/../shared/data PM_TOP=$(CURDIR) PM_BUILD=$(B) $$t 2>&1); rc=$$?; echo "$$out" | grep -v '^Running suite' ; \
	  line=$$(echo "$$out" | grep -E '^[0-9]+%: Checks: ' | tail -1); \
	  r=$$(echo "$$line" | sed -E 's/.*Checks: ([0-9]+).*/\1/'); f=$$(echo "$$line" | sed -E 's/.*Failures: ([0-9]+), Errors: ([0-9]+).*/\1+\2/'); \
	  total_run=$$((total_run + $${r:-0})); total_fail=$$((total_fail + $${f:-1})); \
	  [ $$rc -eq 0 ] || fail=1; \
	done; \
	pct=100; [ $$total_run -gt 0 ] && pct=$$(( (total_run - total_fail) * 100 / total_run )); \
	echo "$$pct%: Checks: $$total_run, Failures: $$total_fail, Errors: 0"; \
	echo "$$((total_run - total_fail)) passed, $$total_fail failed"; \
	exit $$fail
endef

test-run: all check-c89 check-freestanding check-example check-install $(TESTS)
	@$(PYTHON) -c 'import numpy' 2>/dev/null || echo "note: numpy missing; reference tables are committed, regeneration needs python3-numpy"
	$(call run_suites,$(TESTS))

# make sanitize: the core, the host library, pmfit and the Check suites built
# with AddressSanitizer + UndefinedBehaviorSanitizer (any report aborts) in
# build/san, and every suite run against them.  check_firmware and
# check_bench are left out: they build and time separate programs (the ARM
# firmware, the benchmark), not the sanitised library.  Needs build/ (the
# emitted-C test links build/libpm.a), so the plain build runs first.
# check_python runs pytest in a Python interpreter, which would need the
# ASan runtime preloaded into it and a sanitised build of the extension.
SAN_SKIP  := check_firmware check_bench check_python
SAN_TESTS  = $(filter-out $(SAN_SKIP:%=$(B)/tests/%),$(TESTS))
ifneq ($(SAN),)
SAN_FLAGS     := -fsanitize=$(SAN) -fno-sanitize-recover=all -fno-omit-frame-pointer
CORE_FLAGS    += $(SAN_FLAGS)
HOST_CXXFLAGS += $(SAN_FLAGS)
TEST_CFLAGS   += $(SAN_FLAGS)
endif
sanitize: deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory B=build/san SAN=address,undefined sanitize-run

sanitize-run: $(B)/libpm.a $(B)/libpmhost.a $(TOOLS) $(SAN_TESTS)
	@echo "== the Check suites under $(SAN) sanitizers ($(B))"
	$(call run_suites,$(SAN_TESTS))

install: all
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/bin
	install -m 644 include/pm.h $(DESTDIR)$(PREFIX)/include/
	install -m 644 $(B)/libpm.a $(DESTDIR)$(PREFIX)/lib/
	install -m 755 $(B)/libpm.so $(DESTDIR)$(PREFIX)/lib/
	for t in $(TOOLS); do install -m 755 $$t $(DESTDIR)$(PREFIX)/bin/; done
	sed -e 's|@PREFIX@|$(PREFIX)|g' tools/pm.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/pm.pc
	@echo "installed into $(DESTDIR)$(PREFIX)"

clean:
	rm -rf $(B)

# ---------------------------------------------------------------------------
# Benchmarks and the firmware demo (docs/performance.md).
#   make firmware   the mount-controller demo on the host and, under QEMU, on
#                   Cortex-M4F and Cortex-M7; compares with the host, reports
#                   flash, RAM and stack (rules: firmware_demo/firmware.mk)
#   make bench      per-tick cost on the host and the Cortex-M cores, against a
#                   naive evaluation, and fit scaling against LAPACK dgels;
#                   prints a table, writes build/bench/results.json
#                   (rules: bench/bench.mk)
include firmware_demo/firmware.mk
include bench/bench.mk
include bench/fwdchain.mk  # pmbench_fwd_latency: the forward's chain (docs/performance.md)
include tools/plan.mk
# Reliability (docs/reliability.md): make fuzz (libFuzzer targets, bounded
# time; rules: fuzz/fuzz.mk) and make sanitize (the Check suite under ASan +
# UBSan).
-include fuzz/fuzz.mk
# The Python package (docs/python.md): make python, make bench-python; make
# test runs its pytest suite (rules: python/python.mk).
include python/python.mk
include indi/indi.mk  # INDI alignment math plugin: make indi, indi-install (docs/indi.md)

firmware: deps
	@$(MAKE) --no-print-directory firmware-run

bench: deps
	@$(MAKE) --no-print-directory bench-run
# ---------------------------------------------------------------------------
