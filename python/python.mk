# The Python package `pm` (docs/python.md), included from the Makefile.
#   make python        the pybind11 extension and the package, built in place in
#                      build/python/pm/ (PYTHONPATH=build/python), and the C
#                      reference driver the tests compare with (build/python/pm_ref)
#   make bench-python  the vectorised apply against a Python loop over the C call
#                      (bench/bench_python.py; timings, never a test)
#   make bench-python-insns  its instructions per point by width (callgrind)
# make test runs the pytest suite (python/tests) through tests/check_python.c.
#
# The extension is a shared object, so it needs position-independent code:
# the core is built with -fPIC already (CORE_FLAGS); the host library is built
# a second time here with -fPIC into build/python/host/ (the same sources and
# HOST_CXXFLAGS; build/libpmhost.a itself is left as it is).
PY_DIR        := $(B)/python
PY_EXT_SUFFIX := $(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX") or "")' 2>/dev/null)
PY_INCLUDES   := $(patsubst -I%,-isystem %,$(shell $(PYTHON) -m pybind11 --includes 2>/dev/null))
PY_EXT        := $(PY_DIR)/pm/_pm$(PY_EXT_SUFFIX)
PY_HOST_OBJ   := $(HOST_SRC:tools/lib/%.cpp=$(PY_DIR)/host/%.o)
PY_SRC        := $(wildcard python/pm/*.py)
PY_COPY       := $(PY_SRC:python/pm/%=$(PY_DIR)/pm/%)

.PHONY: python bench-python python-check-tools
python: $(PY_EXT) $(PY_COPY) $(PY_DIR)/pm_ref

# A clear message instead of a compiler error when the build tools are missing.
python-check-tools:
	@if [ -z "$(PY_EXT_SUFFIX)" ] || [ -z "$(PY_INCLUDES)" ] || [ ! -f "$$($(PYTHON) -c 'import sysconfig; print(sysconfig.get_paths()["include"])' 2>/dev/null)/Python.h" ]; then \
	  echo "make python: needs $(PYTHON), python3-dev and python3-pybind11 (sh tools/deps.sh installs them)"; exit 1; fi

$(PY_DIR)/host/%.o: tools/lib/%.cpp $(wildcard include/*.h tools/lib/*.hpp tools/lib/*.h)
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -fPIC -c $< -o $@

$(PY_DIR)/libpmhost_pic.a: $(PY_HOST_OBJ)
	@rm -f $@
	$(AR) rcs $@ $^

# The vectorised apply (python/apply_simd.hpp, bit for bit pm_model_apply):
# SSE2 for any x86-64, AVX2 and AVX-512F built with their instructions and
# run only where the CPU has them (apply_lanes.h).  No FMA and no
# contraction: the scalar core has neither on x86-64, and the lanes must
# round as it does (each object is checked for FMA instructions).  (-Wno-psabi:
# the wider vectors are passed only between the inline functions of one file.)
PY_X86_64      := $(filter x86_64,$(shell $(CXX) -dumpmachine | cut -d- -f1))
PY_LANES_OBJ   := $(PY_DIR)/apply_w2.o $(PY_DIR)/apply_w4.o $(PY_DIR)/apply_w8.o
PY_LANES_DEPS  := python/apply_simd.hpp python/apply_lanes.h lib/pm_detail.hpp include/pm.h
$(PY_DIR)/apply_w4.o: PY_ISA := $(if $(PY_X86_64),-mavx2 -mno-fma)
$(PY_DIR)/apply_w8.o: PY_ISA := $(if $(PY_X86_64),-mavx512f -mno-fma)

# A core built with FMA (OPT=-march=native, say) rounds otherwise: then the
# lanes are left out (-DPM_LANES_OFF: apply calls pm_model_apply per point).
$(PY_DIR)/apply_w%.o: python/apply_w%.cpp $(PY_LANES_DEPS) $(B)/libpm.a
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -fPIC -ffp-contract=off -Wno-psabi $(PY_ISA) \
	  $$(objdump -d $(B)/libpm.a | grep -qE '\svfn?m(add|sub)' && echo -DPM_LANES_OFF) -c $< -o $@
	@if objdump -d $@ | grep -qE '\svfn?m(add|sub)'; then \
	  echo "$@: FMA instructions in the lanes (they must round as the scalar core)"; rm -f $@; exit 1; fi

$(PY_EXT): python/_pm.cpp $(PY_LANES_OBJ) $(PY_DIR)/libpmhost_pic.a $(B)/libpm.a $(wildcard include/*.h tools/lib/*.hpp tools/lib/*.h python/*.h) | python-check-tools
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -Ipython -fPIC -pthread -fvisibility=hidden -shared $(PY_INCLUDES) $< -o $@ \
	  $(PY_LANES_OBJ) $(PY_DIR)/libpmhost_pic.a $(B)/libpm.a -lerfa -lm

$(PY_DIR)/pm/%.py: python/pm/%.py
	@mkdir -p $(@D)
	cp $< $@

# The reference the tests compare with: the C API called from C.
$(PY_DIR)/pm_ref: python/tests/pm_ref.c $(B)/libpmhost.a $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(B)/libpmhost.a $(B)/libpm.a -lerfa -lstdc++ -lm

# make test builds the package before the suite that runs pytest on it.
$(B)/tests/check_python: $(PY_EXT) $(PY_COPY) $(PY_DIR)/pm_ref $(B)/pmfit

bench-python: python $(B)/pmfit
	PYTHONPATH=$(CURDIR)/$(PY_DIR) $(PYTHON) bench/bench_python.py

# Instructions per point of the vectorised apply by width (callgrind).
.PHONY: bench-python-insns
bench-python-insns: python
	PYTHONPATH=$(CURDIR)/$(PY_DIR) $(PYTHON) bench/bench_lanes_insns.py

# make demo ends with the package's example (examples/python_demo.py).
.PHONY: python-demo
python-demo: python
	@echo; echo "== the Python package (docs/python.md): examples/python_demo.py"
	PYTHONPATH=$(CURDIR)/$(PY_DIR) $(PYTHON) examples/python_demo.py
