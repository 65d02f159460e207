# fuzz/fuzz.mk - libFuzzer targets (included by the top-level Makefile).
#   make fuzz                 build every target into $(B)/fuzz/ and run each
#                             for FUZZ_SECONDS (default 60) on a scratch copy
#                             of its corpus; one summary line per target;
#                             fails if any target crashed
#   make fuzz-build           only build them
#   make fuzz-merge           merge what the last runs found into the
#                             committed corpora (fuzz/corpus/<target>/,
#                             minimised by libFuzzer's -merge=1); deliberate
#   make -j2 fuzz             two targets at a time
# Needs clang 14 and its libFuzzer runtime (Debian: clang-14,
# libclang-rt-14-dev).  fuzz/README.md describes targets and invariants.
FUZZ_CC      ?= clang-14
FUZZ_CXX     ?= clang++-14
FUZZ_SECONDS ?= 60
FUZZ_FLAGS   ?= -rss_limit_mb=2048
# Seconds one input may run (a hang detector; slower ones are also written
# out as slow units, which fail the run): 10, but 60 for explain, whose
# whole pipeline takes 0.4-0.6 s on a run of 75-140 lines in the release
# build and 10-20 times that instrumented (fuzz/README.md).
FUZZ_TIMEOUT ?= 10
FUZZ_TIMEOUT_explain ?= 60
FUZZ_TARGETS := runfile modelfile capi fit explain plan
FUZZ_DIR     := $(B)/fuzz
# Instrumentation for every object; the libFuzzer main at the link.
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_OPT     := -O1 -g
FUZZ_CORE_FLAGS := $(filter-out $(OPT),$(CORE_FLAGS)) $(FUZZ_OPT) $(FUZZ_SAN) -fsanitize=fuzzer-no-link
FUZZ_HOST_FLAGS := $(filter-out $(OPT),$(HOST_CXXFLAGS)) $(FUZZ_OPT) $(FUZZ_SAN) -fsanitize=fuzzer-no-link
# FUZZ_DEFS: extra -D flags for the harnesses (none needed).
FUZZ_DEFS    ?=
FUZZ_C_FLAGS    := -std=c99 $(FUZZ_OPT) -Wall -Wextra -Iinclude -Itools/lib -Ifuzz $(FUZZ_SAN) \
                   -fsanitize=fuzzer-no-link $(FUZZ_DEFS)
FUZZ_CORE_OBJ := $(CORE_SRC:lib/%.cpp=$(FUZZ_DIR)/obj/core/%.o)
# explain links the core without coverage tracing (still ASan + UBSan): the
# fit's inner loops compare doubles millions of times per input, and the
# tracing of each comparison made one 75-line input take 195 s (5 s
# without it); the core's own targets (fit, capi) keep their coverage.
FUZZ_CORE_NOCOV_OBJ := $(CORE_SRC:lib/%.cpp=$(FUZZ_DIR)/obj/core_nocov/%.o)
FUZZ_HOST_OBJ := $(HOST_SRC:tools/lib/%.cpp=$(FUZZ_DIR)/obj/host/%.o)
FUZZ_HARNESS_OBJ := $(FUZZ_TARGETS:%=$(FUZZ_DIR)/obj/harness_%.o)
FUZZ_BINS    := $(FUZZ_TARGETS:%=$(FUZZ_DIR)/fuzz_%)
FUZZ_HEADERS := $(wildcard fuzz/*.h include/*.h tools/lib/*.h)
# The real runs (not in the repository) as extra run-file seeds when present.
FUZZ_SHARED  ?= ../shared/data

.PHONY: fuzz fuzz-build fuzz-merge $(FUZZ_TARGETS:%=fuzz-run-%)

$(FUZZ_DIR)/obj/core/%.o: lib/%.cpp $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(FUZZ_CORE_FLAGS) -c $< -o $@

$(FUZZ_DIR)/obj/core_nocov/%.o: lib/%.cpp $(wildcard include/*.h lib/*.hpp)
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(filter-out -fsanitize=fuzzer-no-link,$(FUZZ_CORE_FLAGS)) -c $< -o $@

$(FUZZ_DIR)/obj/host/%.o: tools/lib/%.cpp $(wildcard include/*.h tools/lib/*.hpp tools/lib/*.h)
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(FUZZ_HOST_FLAGS) -c $< -o $@

$(FUZZ_DIR)/obj/%.o: fuzz/%.c $(FUZZ_HEADERS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_C_FLAGS) -c $< -o $@

$(FUZZ_DIR)/fuzz_%: $(FUZZ_DIR)/obj/fuzz_%.o $(FUZZ_DIR)/obj/harness_%.o $(FUZZ_HOST_OBJ) $(FUZZ_CORE_OBJ)
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ -o $@ -lerfa -lm

$(FUZZ_DIR)/fuzz_explain: $(FUZZ_DIR)/obj/fuzz_explain.o $(FUZZ_DIR)/obj/harness_explain.o \
                          $(FUZZ_HOST_OBJ) $(FUZZ_CORE_NOCOV_OBJ)
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ -o $@ -lerfa -lm

fuzz-build: $(FUZZ_BINS)

# One target: a scratch corpus (the committed seeds, the regression inputs
# and, for the run-file reader, ../shared/data with a 0 option byte), a
# bounded run, and a summary in $(FUZZ_DIR)/work/<target>/summary.
$(FUZZ_TARGETS:%=fuzz-run-%): fuzz-run-%: $(FUZZ_DIR)/fuzz_%
	@w=$(FUZZ_DIR)/work/$*; rm -rf $$w; mkdir -p $$w/corpus $$w/artifacts; \
	for f in fuzz/corpus/$*/* fuzz/regress/$*/*; do [ -f "$$f" ] && cp "$$f" $$w/corpus/; done; \
	if [ "$*" = runfile ] && [ -d "$(FUZZ_SHARED)" ]; then \
	  for f in $$(find "$(FUZZ_SHARED)" -name '*.dat'); do \
	    { printf '\000'; cat "$$f"; } > $$w/corpus/shared_$$(echo $$f | tr '/.' '__'); done; \
	fi; \
	$(FUZZ_DIR)/fuzz_$* -max_total_time=$(FUZZ_SECONDS) $(FUZZ_FLAGS) \
	  -timeout=$(or $(FUZZ_TIMEOUT_$*),$(FUZZ_TIMEOUT)) \
	  -report_slow_units=$(or $(FUZZ_TIMEOUT_$*),$(FUZZ_TIMEOUT)) -print_final_stats=1 \
	  -artifact_prefix=$$w/artifacts/ $$w/corpus > $$w/log 2>&1; rc=$$?; \
	runs=$$(sed -n 's/^stat::number_of_executed_units: *//p' $$w/log | tail -1); \
	secs=$$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' $$w/log | tail -1); \
	cov=$$(grep -Eo 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+' $$w/log | tail -1); \
	rate=$$(sed -n 's/^stat::average_exec_per_sec: *//p' $$w/log | tail -1); \
	arts=$$(ls $$w/artifacts | tr '\n' ' '); \
	if [ $$rc -eq 0 ] && [ -z "$$arts" ]; then res=ok; else res="FAILED (exit $$rc; $$w/log; artifacts: $$arts)"; fi; \
	echo "fuzz_$*: $${secs:-?} s, $${runs:-?} runs ($${rate:-?}/s), $${cov:-no coverage line}: $$res" > $$w/summary; \
	cat $$w/summary

fuzz: $(FUZZ_TARGETS:%=fuzz-run-%)
	@echo "== fuzz summary ($(FUZZ_SECONDS) s per target)"
	@fail=0; for t in $(FUZZ_TARGETS); do cat $(FUZZ_DIR)/work/$$t/summary; \
	  grep -q ': ok$$' $(FUZZ_DIR)/work/$$t/summary || fail=1; done; exit $$fail

fuzz-merge: $(FUZZ_BINS)
	@for t in $(FUZZ_TARGETS); do \
	  [ -d $(FUZZ_DIR)/work/$$t/corpus ] || continue; mkdir -p fuzz/corpus/$$t; \
	  $(FUZZ_DIR)/fuzz_$$t -merge=1 fuzz/corpus/$$t $(FUZZ_DIR)/work/$$t/corpus \
	    > $(FUZZ_DIR)/work/$$t/merge.log 2>&1 || exit 1; \
	  echo "fuzz-merge: $$t: $$(ls fuzz/corpus/$$t | wc -l) files in fuzz/corpus/$$t"; done

# The regression test compiles the harness sources in.
$(B)/tests/check_fuzz_regress: $(wildcard fuzz/*.c fuzz/*.h)

# Keep the objects (they are intermediate files of the pattern rules).
.SECONDARY: $(FUZZ_CORE_OBJ) $(FUZZ_CORE_NOCOV_OBJ) $(FUZZ_HOST_OBJ) $(FUZZ_HARNESS_OBJ) $(FUZZ_TARGETS:%=$(FUZZ_DIR)/obj/fuzz_%.o)
