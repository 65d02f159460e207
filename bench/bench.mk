# bench/bench.mk - build and run rules of "make bench" (included by the
# top-level Makefile after firmware_demo/firmware.mk, whose toolchain
# variables, target flags and fw_core template it uses).
#
#   build/bench/pmbench          host per-call cost (TSC ticks; --callgrind)
#   build/bench/pmbench_fit      fit scaling, ours vs LAPACK dgels
#   build/bench/pmbench_explain  pmfit explain's time on 1,000-30,000 points
#   build/bench/<t>/bench.elf    Cortex-M per-call instructions (t = m4f, m7),
#                                with the core at PM_MAX_L=4
#   build/bench/results.json     everything, merged by bench/report.py
#
# The host programs link build/libpm.a, the library as shipped (CORE_FLAGS,
# PM_MAX_L=4).  naive.c is compiled with the compiler's default
# floating-point flags: the paper's formulas as a user would write them.
# BENCH_MAX_N (default 1000000) bounds the fit sizes; BENCH_BATCHES (31) the
# timing batches.

BN            := $(B)/bench
BENCH_MAX_N   ?= 1000000
BENCH_BATCHES ?= 31
# the distribution bench: timing rounds per call; callgrind dumps every K-th call
DIST_ROUNDS   ?= 15
DIST_CG_EVERY ?= 4
# each Cortex-M bench ELF measures both the double and the float build
BENCH_TARGETS := m4f m7
BENCH_CFLAGS  := -std=gnu99 $(OPT) -g -Wall -Wextra -Iinclude -Ibench -Ifirmware_demo
BENCH_SRC_H   := bench/bench_common.h bench/naive.h bench/host_timer.h include/pm.h

$(BN)/host/naive.o: bench/naive.c $(BENCH_SRC_H)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -c $< -o $@

$(BN)/pmbench: bench/bench_host.c bench/bench_common.c $(BN)/host/naive.o $(BENCH_SRC_H) $(B)/libpm.a
	$(CC) $(BENCH_CFLAGS) bench/bench_host.c bench/bench_common.c $(BN)/host/naive.o \
	  $(B)/libpm.a -lm -o $@

$(BN)/pmbench_fit: bench/bench_fit.c include/pm.h $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) $< $(B)/libpm.a -llapacke -llapack -lblas -lm -o $@

$(BN)/pmbench_explain: bench/bench_explain.c include/pm.h tools/lib/explain.h tools/lib/simulate.h \
                       $(B)/libpmhost.a $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -Itools/lib $< $(B)/libpmhost.a $(B)/libpm.a -lerfa -lstdc++ -lm -o $@

# $(call bench_target,T): the Cortex-M bench of target T.
define bench_target
$(call fw_core,$(BN)/$(1),$$(ARM_CXX),$$(FW_ARM_CXXFLAGS) $$(FW_CPU_$(1)),4)

$(BN)/$(1)/%.o: bench/%.c $$(BENCH_SRC_H) firmware_demo/fw_platform.h
	@mkdir -p $$(@D)
	$$(ARM_CC) $$(BENCH_CFLAGS) $$(FW_CPU_$(1)) -ffunction-sections -fdata-sections \
	  -DPM_MAX_L=4 -c $$< -o $$@

$(BN)/$(1)/platform_cm.o: firmware_demo/platform_cm.c firmware_demo/fw_platform.h
	@mkdir -p $$(@D)
	$$(ARM_CC) $$(FW_ARM_PLATFLAGS) $$(FW_CPU_$(1)) -DFW_TARGET_NAME='"$(1)"' -c $$< -o $$@

$(BN)/$(1)/bench.elf: $(addprefix $(BN)/$(1)/,bench_cm.o bench_common.o naive.o platform_cm.o) \
                      $(addprefix $(BN)/$(1)/core/,$(FW_CORE_NAMES)) firmware_demo/cortex_m.ld
	$$(ARM_CC) $$(FW_CPU_$(1)) $$(filter %.o,$$^) -o $$@ $$(FW_ARM_LDFLAGS) -lm
endef
$(foreach t,$(BENCH_TARGETS),$(eval $(call bench_target,$(t))))

BENCH_ELFS := $(foreach t,$(BENCH_TARGETS),$(BN)/$(t)/bench.elf)

# --- issue 18: the inverse's cost as a distribution (bench/dist.h) -------
# pmbench_dist (TSC ticks; --callgrind: one dump per call), pmbench_dist_probe
# (model evaluations: the core with the counter of tests/probe.h, the objects
# check_bounded uses), <t>/dist.elf (Cortex-M instructions per call).
DIST_SRC := bench/dist.c bench/bench_common.c
DIST_H   := bench/dist.h bench/bench_common.h bench/host_timer.h tests/hard_cases.h tests/testutil.h include/pm.h

$(BN)/pmbench_dist: bench/bench_dist_host.c $(DIST_SRC) $(DIST_H) $(BN)/host/naive.o $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -Itests bench/bench_dist_host.c $(DIST_SRC) $(BN)/host/naive.o \
	  $(B)/libpm.a -lm -o $@

$(BN)/pmbench_dist_probe: bench/bench_dist_host.c $(DIST_SRC) $(DIST_H) $(BN)/host/naive.o \
                          $(PROBE_OBJ)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -Itests -DDIST_PROBE bench/bench_dist_host.c $(DIST_SRC) \
	  $(BN)/host/naive.o $(PROBE_OBJ) -lstdc++ -lm -o $@

# $(call dist_target,T): the Cortex-M distribution bench of target T (the
# objects of the bench's core, PM_MAX_L=4).
define dist_target
$(BN)/$(1)/dist/%.o: bench/%.c $$(DIST_H) bench/dist.h firmware_demo/fw_platform.h
	@mkdir -p $$(@D)
	$$(ARM_CC) $$(BENCH_CFLAGS) -Itests $$(FW_CPU_$(1)) -ffunction-sections -fdata-sections \
	  -DPM_MAX_L=4 -c $$< -o $$@

$(BN)/$(1)/dist.elf: $(addprefix $(BN)/$(1)/dist/,bench_dist_cm.o dist.o bench_common.o) \
                     $(BN)/$(1)/naive.o $(BN)/$(1)/platform_cm.o \
                     $(addprefix $(BN)/$(1)/core/,$(FW_CORE_NAMES)) firmware_demo/cortex_m.ld
	$$(ARM_CC) $$(FW_CPU_$(1)) $$(filter %.o,$$^) -o $$@ $$(FW_ARM_LDFLAGS) -lm
endef
$(foreach t,$(BENCH_TARGETS),$(eval $(call dist_target,$(t))))

DIST_ELFS := $(foreach t,$(BENCH_TARGETS),$(BN)/$(t)/dist.elf)

# The dearest tracking ticks on the Cortex-M7 (bench/track_worst_cm.c: the
# steady-state ticks check_bounded bounds; PM_BUDGET_M7_TRACK_INSNS).
$(BN)/m7/track_worst.elf: $(BN)/m7/dist/track_worst_cm.o $(BN)/m7/platform_cm.o \
                          $(addprefix $(BN)/m7/core/,$(FW_CORE_NAMES)) firmware_demo/cortex_m.ld
	$(ARM_CC) $(FW_CPU_m7) $(filter %.o,$^) -o $@ $(FW_ARM_LDFLAGS) -lm

bench-track-worst: fw-toolchain $(BN)/m7/track_worst.elf
	timeout 600 $(QEMU_ARM) -M $(FW_MACHINE_m7) -nographic -semihosting \
	  -icount shift=0,align=off,sleep=off -kernel $(BN)/m7/track_worst.elf

.PHONY: bench-track-worst


bench-run: fw-toolchain $(BN)/pmbench $(BN)/pmbench_fit $(BN)/pmbench_explain $(BENCH_ELFS) \
           $(BN)/pmbench_dist $(BN)/pmbench_dist_probe $(DIST_ELFS)
	@command -v valgrind > /dev/null || { echo "bench: valgrind not found (tools/deps.sh)"; exit 1; }
	@echo "== host: TSC ticks per call ($(BENCH_BATCHES) batches of 256 calls, median)"
	$(BN)/pmbench --batches $(BENCH_BATCHES) --out $(BN)/host.jsonl
	@echo "== host: instructions per call (callgrind)"
	@rm -rf $(BN)/callgrind && mkdir -p $(BN)/callgrind
	valgrind --tool=callgrind --callgrind-out-file=$(BN)/callgrind/cg.out \
	  $(BN)/pmbench --callgrind > $(BN)/callgrind/log.txt 2>&1
	@$(foreach t,$(BENCH_TARGETS),echo "== $(t): instructions per call under QEMU" && \
	  timeout 600 $(QEMU_ARM) -M $(FW_MACHINE_$(t)) \
	  -nographic -semihosting -icount shift=0,align=off,sleep=off -kernel $(BN)/$(t)/bench.elf \
	  > $(BN)/$(t).out 2>&1 || { cat $(BN)/$(t).out; exit 1; };)
	@echo "== the inverse per situation (bench/dist.h): evaluations, host ticks, instructions"
	$(BN)/pmbench_dist_probe --out $(BN)/dist_evals.jsonl
	$(BN)/pmbench_dist --rounds $(DIST_ROUNDS) --out $(BN)/dist_host.jsonl
	@rm -rf $(BN)/callgrind_dist && mkdir -p $(BN)/callgrind_dist
	valgrind --tool=callgrind --callgrind-out-file=$(BN)/callgrind_dist/cg.out --dump-instr=no \
	  --dump-line=no $(BN)/pmbench_dist --callgrind --every $(DIST_CG_EVERY) \
	  > $(BN)/callgrind_dist/log.txt 2>&1
	@$(foreach t,$(BENCH_TARGETS),echo "== $(t): instructions of each inverse under QEMU" && \
	  timeout 900 $(QEMU_ARM) -M $(FW_MACHINE_$(t)) \
	  -nographic -semihosting -icount shift=0,align=off,sleep=off -kernel $(BN)/$(t)/dist.elf \
	  > $(BN)/$(t)_dist.out 2>&1 || { cat $(BN)/$(t)_dist.out; exit 1; };)
	@echo "== fit scaling (N up to $(BENCH_MAX_N)); ours vs LAPACK dgels"
	$(BN)/pmbench_fit --max-n $(BENCH_MAX_N) --out $(BN)/fit.jsonl
	@echo "== pmfit explain on large runs"
	$(BN)/pmbench_explain --out $(BN)/explain.jsonl
	$(PYTHON) tests/ref/indep_gen.py $(BN)/indep10k.dat --mount gem --n 10000 --seed 5 \
	  --noise 1 --index-deg 3 --geom 120 --aniso 600 --effect refraction=-3 \
	  --effect ha_periodic=1.5:240
	$(BN)/pmbench_explain --file $(BN)/indep10k.dat explain_indep10k_aniso600 \
	  --out $(BN)/explain.jsonl
	@$(PYTHON) bench/report.py --dir $(BN) --targets "$(BENCH_TARGETS)"

.PHONY: bench-run

# The numbers behind the stateless inverse's floor (docs/performance.md,
# stop 32): the bounds it certifies with, |D| and the real |J|.
$(BN)/pminv_floor: bench/inv_floor.c bench/bench_common.c $(BN)/host/naive.o $(BENCH_SRC_H) \
                   $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) bench/inv_floor.c bench/bench_common.c $(BN)/host/naive.o \
	  $(B)/libpm.a -lstdc++ -lm -o $@

# The double inverse's outcomes on large samples (issue 18, round 3):
# pmbench_inv_stress real [N] [SEED] | hard (bench/inv_stress.c).
$(BN)/pmbench_inv_stress: bench/inv_stress.c tests/hard_cases.h tests/testutil.h tests/probe.h \
                          include/pm.h $(PROBE_OBJ)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -Itests $< $(PROBE_OBJ) -lstdc++ -lm -o $@
