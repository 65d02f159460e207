# firmware_demo/firmware.mk - build rules of "make firmware" (included by the
# top-level Makefile, which defines B, CC, CXX, CORE_FLAGS, OPT, PYTHON).
#
#   build/fw/gen/fw_model.h       pmfit fit examples/sim_gem.dat --order 2 --emit-c
#   build/fw/host/demo            host build of the demo (PM_MAX_L=2)
#   build/fw/gen/fw_ref.h         its results: the reference for the targets
#   build/fw/<t>/demo.elf         t = m4f (Cortex-M4F), m7 (Cortex-M7)
#   build/fw/<t>/core/*.o         the core, built for the target
#
# The core is compiled for the targets with the Makefile's CORE_FLAGS (the
# freestanding flags) minus -fPIC, plus the CPU flags, -ffunction-sections
# and the stack-usage and call-graph dumps (firmware_demo/fwcheck.py).
#
# Targets: m4f and m7 track with the double evaluation (on the M4F's
# single-precision FPv4-SP every double operation is emulated by libgcc:
# the baseline), m4f_float with the float build (pm_model_f, -DFW_FLOAT,
# compared with the host to 0.01"), linked with m4f's core objects.  A
# target is one entry of FW_TARGETS with its CPU flags, machine, defines
# and (optionally) the target whose core it shares.

ARM_CC    ?= arm-none-eabi-gcc
ARM_CXX   ?= arm-none-eabi-g++
ARM_SIZE  ?= arm-none-eabi-size
QEMU_ARM  ?= qemu-system-arm

FW        := $(B)/fw
FW_GEN    := $(FW)/gen
FW_L      := 2
FW_RUN    := examples/sim_gem.dat
FW_TARGETS := m4f m7 m4f_float

FW_CPU_m4f     := -mthumb -mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard
FW_CPU_m7      := -mthumb -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard
FW_MACHINE_m4f := mps2-an386
FW_MACHINE_m7  := mps2-an500
FW_DEFS_m4f    :=
FW_DEFS_m7     :=
FW_CPU_m4f_float     := $(FW_CPU_m4f)
FW_MACHINE_m4f_float := mps2-an386
FW_DEFS_m4f_float    := -DFW_FLOAT
FW_COREOF_m4f_float  := m4f
# the directory of target T's core objects
fw_coredir = $(FW)/$(or $(FW_COREOF_$(1)),$(1))/core

FW_ARM_DUMPS   := -ffunction-sections -fdata-sections -fstack-usage -fcallgraph-info=su
FW_ARM_CXXFLAGS = $(filter-out -fPIC,$(CORE_FLAGS)) $(FW_ARM_DUMPS)
FW_ARM_CFLAGS   = -std=c89 -pedantic -Werror -Wall -Wextra $(OPT) -g -Iinclude \
                  -Ifirmware_demo -I$(FW_GEN) $(FW_ARM_DUMPS)
FW_ARM_LDFLAGS  = -T firmware_demo/cortex_m.ld -nostartfiles --specs=rdimon.specs \
                  -Wl,--gc-sections
# the start-up code needs GCC extensions (attributes, inline assembly)
FW_ARM_PLATFLAGS = -std=gnu99 -Werror -Wall -Wextra $(OPT) -g -Ifirmware_demo $(FW_ARM_DUMPS)
FW_HOST_CFLAGS  = -std=c89 -pedantic -Werror -Wall -Wextra $(OPT) -g -Iinclude \
                  -Ifirmware_demo -I$(FW_GEN)
FW_CORE_NAMES  := $(notdir $(CORE_SRC:.cpp=.o))
FW_CORE_DEPS   := $(wildcard include/*.h lib/*.hpp)

# $(call fw_core,DIR,COMPILER,FLAGS,MAX_L): the core's objects in DIR/core/.
define fw_core
$(1)/core/%.o: lib/%.cpp $$(FW_CORE_DEPS)
	@mkdir -p $$(@D)
	$(2) $(3) -DPM_MAX_L=$(4) -c $$< -o $$@
endef

# --- host reference -----------------------------------------------------
$(eval $(call fw_core,$(FW)/host,$$(CXX),$$(CORE_FLAGS),$(FW_L)))

$(FW_GEN)/fw_model.h: $(B)/pmfit $(FW_RUN)
	@mkdir -p $(@D)
	$(B)/pmfit fit $(FW_RUN) --order $(FW_L) --emit-c $@ > $(FW_GEN)/fit.txt

$(FW)/host/demo: firmware_demo/demo.c firmware_demo/platform_host.c firmware_demo/fw_platform.h \
                 $(FW_GEN)/fw_model.h $(addprefix $(FW)/host/core/,$(FW_CORE_NAMES))
	$(CC) $(FW_HOST_CFLAGS) -DFW_HOSTED -DPM_MAX_L=$(FW_L) firmware_demo/demo.c \
	  firmware_demo/platform_host.c $(addprefix $(FW)/host/core/,$(FW_CORE_NAMES)) -lm -o $@

$(FW_GEN)/fw_ref.h: $(FW)/host/demo
	$(FW)/host/demo --emit-ref $@ > $(FW)/host/demo-ref.out

# --- Cortex-M targets ----------------------------------------------------
# $(call fw_target,T): core (unless shared), demo objects and demo.elf of T.
define fw_target
$(if $(FW_COREOF_$(1)),,$(call fw_core,$(FW)/$(1),$$(ARM_CXX),$$(FW_ARM_CXXFLAGS) $$(FW_CPU_$(1)),$(FW_L)))

$(FW)/$(1)/platform_cm.o: firmware_demo/platform_cm.c firmware_demo/fw_platform.h
	@mkdir -p $$(@D)
	$$(ARM_CC) $$(FW_ARM_PLATFLAGS) $$(FW_CPU_$(1)) -DFW_TARGET_NAME='"$(1)"' -c $$< -o $$@

$(FW)/$(1)/demo.o: firmware_demo/demo.c firmware_demo/fw_platform.h $(FW_GEN)/fw_model.h \
                   $(FW_GEN)/fw_ref.h include/pm.h
	@mkdir -p $$(@D)
	$$(ARM_CC) $$(FW_ARM_CFLAGS) $$(FW_CPU_$(1)) $$(FW_DEFS_$(1)) -DFW_REF \
	  -DPM_MAX_L=$(FW_L) -c $$< -o $$@

$(FW)/$(1)/demo.elf: $(FW)/$(1)/demo.o $(FW)/$(1)/platform_cm.o \
                     $(addprefix $(call fw_coredir,$(1))/,$(FW_CORE_NAMES)) firmware_demo/cortex_m.ld
	$$(ARM_CC) $$(FW_CPU_$(1)) $$(filter %.o,$$^) -o $$@ $$(FW_ARM_LDFLAGS) \
	  -Wl,-Map=$(FW)/$(1)/demo.map -lm
endef
$(foreach t,$(FW_TARGETS),$(eval $(call fw_target,$(t))))

FW_ELFS := $(foreach t,$(FW_TARGETS),$(FW)/$(t)/demo.elf)

fw-toolchain:
	@for t in $(ARM_CC) $(QEMU_ARM); do command -v $$t > /dev/null || { \
	  echo "firmware: $$t not found (sh tools/deps.sh installs gcc-arm-none-eabi," \
	       "libnewlib-arm-none-eabi, qemu-system-arm)"; exit 1; }; done

# Build, run on the host and under QEMU, compare, report sizes and stack.
firmware-run: fw-toolchain $(FW)/host/demo $(FW_ELFS)
	@$(PYTHON) firmware_demo/fwcheck.py --build $(FW) --targets "$(FW_TARGETS)" \
	  --machines "$(foreach t,$(FW_TARGETS),$(FW_MACHINE_$(t)))" \
	  --qemu $(QEMU_ARM) --size $(ARM_SIZE) \
	  --coreof "$(strip $(foreach t,$(FW_TARGETS),$(if $(FW_COREOF_$(t)),$(t)=$(FW_COREOF_$(t)))))"

.PHONY: fw-toolchain firmware-run
