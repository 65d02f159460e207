# INDI alignment math plugin (docs/indi.md).  Included from the Makefile.
#   make indi           build/indi/libindi_pm_MathPlugin.so (and the test fixtures)
#   make indi-install   install it where INDI looks for math plugins
#                       (INDI_PLUGIN_DIR; DESTDIR honoured; as root)
#   make indi-e2e       the end-to-end run against indiserver and the
#                       AstroTrac simulator, all four plugins compared
#                       (tests/check_indi.c runs it for pm and the built-in)
# Needs libindi-dev, libnova-dev (tools/deps.sh).
INDI_PC         := $(shell pkg-config --exists libindi 2>/dev/null && echo yes)
INDI_LIBDIR     := $(shell pkg-config --variable=libdir libindi 2>/dev/null)
INDI_PLUGIN_DIR ?= $(if $(INDI_LIBDIR),$(INDI_LIBDIR),/usr/lib/x86_64-linux-gnu)/indi/MathPlugins
INDI_INC        := -isystem /usr/include/libindi
INDI_PLUGIN     := $(B)/indi/libindi_pm_MathPlugin.so
INDI_SHIM       := $(B)/indi/libpm_indi_testshim.so

.PHONY: indi indi-install indi-e2e indi-check-deps

indi-check-deps:
	@test -f /usr/include/libindi/alignment/MathPlugin.h || \
	  { echo "make indi: INDI development headers missing (sh tools/deps.sh installs libindi-dev)"; exit 1; }
	@test -f /usr/include/libnova/sidereal_time.h || \
	  { echo "make indi: libnova headers missing (sh tools/deps.sh installs libnova-dev)"; exit 1; }

# The fitting logic alone (no INDI): the plugin and tests/check_indi.c use it.
$(B)/indi/pm_indi.o: indi/pm_indi.cpp indi/pm_indi.h include/pm.h
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -fPIC -Iindi -c $< -o $@

$(B)/indi/pm_math_plugin.o: indi/pm_math_plugin.cpp indi/pm_indi.h include/pm.h | indi-check-deps
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -fPIC -Iindi $(INDI_INC) -c $< -o $@

# Exports Create, Destroy, GetDisplayName (what INDI's MathPluginManagement
# dlopens); the core is linked in statically.
$(INDI_PLUGIN): $(B)/indi/pm_math_plugin.o $(B)/indi/pm_indi.o $(B)/libpm.a
	$(CXX) -shared -o $@ $^ -lindiAlignmentDriver -lindidriver -lnova -lm

# Test fixture (LD_PRELOAD): frozen sky, plugin directory redirect.
$(INDI_SHIM): indi/testshim.c
	@mkdir -p $(@D)
	$(CC) -shared -fPIC -O2 -Wall -Wextra $< -o $@ -ldl

# A plugin directory for the test: INDI's own plugins (linked) and ours.
$(B)/indi/MathPlugins/.stamp: $(INDI_PLUGIN)
	@rm -rf $(@D) && mkdir -p $(@D)
	@for f in $(INDI_PLUGIN_DIR)/*.so; do [ -e "$$f" ] && ln -s "$$f" $(@D)/; done; true
	ln -s $(abspath $(INDI_PLUGIN)) $(@D)/
	@touch $@

# Loads the plugin as INDI does and checks its transforms (tests/check_indi.c).
$(B)/indi/pm_indi_probe: indi/pm_indi_probe.cpp | indi-check-deps
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) $(INDI_INC) $< -o $@ -lindiAlignmentDriver -lindidriver -lnova -ldl -lm

indi: $(INDI_PLUGIN) $(INDI_SHIM) $(B)/indi/MathPlugins/.stamp $(B)/indi/pm_indi_probe

indi-install: $(INDI_PLUGIN)
	install -d $(DESTDIR)$(INDI_PLUGIN_DIR)
	install -m 755 $(INDI_PLUGIN) $(DESTDIR)$(INDI_PLUGIN_DIR)/
	@echo "installed $(notdir $(INDI_PLUGIN)) into $(DESTDIR)$(INDI_PLUGIN_DIR)"

INDI_E2E_PLUGINS ?= "pm Math Plugin" INBUILT_MATH_PLUGIN "Nearest Math Plugin" "SVD Math Plugin"
indi-e2e: indi
	$(PYTHON) indi/e2e_indi.py --build $(B) --plugin-dir $(INDI_PLUGIN_DIR) --plugins $(INDI_E2E_PLUGINS)

# make demo ends with the plugin's transforms in-process (seconds); the end-to-end run
# with indiserver is make indi-e2e (minutes).
.PHONY: indi-demo
indi-demo:
	@if [ -f /usr/include/libindi/alignment/MathPlugin.h ] && [ -f /usr/include/libnova/sidereal_time.h ]; then \
	  $(MAKE) --no-print-directory -s indi && \
	  echo "== INDI math plugin ($(INDI_PLUGIN); docs/indi.md): transforms against a known mount" && \
	  for m in eq altaz; do LD_PRELOAD=$(INDI_SHIM) PM_INDI_FROZEN_JD=2460310.75 $(B)/indi/pm_indi_probe $(INDI_PLUGIN) $$m \
	    2>/dev/null | grep '^probe: '; done; \
	  echo "   (end to end with indiserver and the AstroTrac simulator: make indi-e2e; install: make indi-install)"; \
	else echo "(INDI headers missing: the INDI math plugin is skipped; sh tools/deps.sh installs them)"; fi

# tests/check_indi.c: the fitting logic linked in.
$(B)/tests/check_indi: tests/check_indi.c $(B)/indi/pm_indi.o $(B)/libpmhost.a $(B)/libpm.a $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) -Iindi $< -o $@ $(B)/indi/pm_indi.o $(B)/libpmhost.a $(B)/libpm.a $(TEST_LIBS)
