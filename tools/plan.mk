# tools/plan.mk - make rules of issue 17's planning work (docs/model.md, "Which
# star next").  Included by the top-level Makefile.
#
#   make bench-plan   build/bench/pmbench_plan: points needed for a given
#                     held-out / cross-validated pointing error, plan vs grids
#                     and random stars, simulated and on the real runs in
#                     ../shared/data; prints the tables, writes
#                     build/bench/plan.jsonl and plan.txt.  Part of make bench.
#   check_plan        links examples/next_star.c (a controller choosing its next
#                     star with the C API), compiled as strict C89.
.PHONY: bench-plan
$(B)/bench/pmbench_plan: bench/bench_plan.cpp $(B)/libpmhost.a $(B)/libpm.a $(wildcard tools/lib/*.hpp)
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) $< -o $@ $(B)/libpmhost.a $(B)/libpm.a -lerfa -lm

bench-plan: $(B)/bench/pmbench_plan
	$(B)/bench/pmbench_plan --data $(DATA) --out $(B)/bench/plan.jsonl > $(B)/bench/plan.txt
	@cat $(B)/bench/plan.txt

bench-run: bench-plan

$(B)/examples/next_star.o: examples/next_star.c include/pm.h
	@mkdir -p $(@D)
	$(CC) -std=c89 -pedantic -Werror -Wall -Wextra $(OPT) -g $(SAN_FLAGS) -Iinclude -c $< -o $@

$(B)/tests/check_plan: tests/check_plan.c $(B)/examples/next_star.o $(B)/libpmhost.a $(B)/libpm.a $(wildcard tests/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CFLAGS) $< -o $@ $(B)/examples/next_star.o $(B)/libpmhost.a $(B)/libpm.a $(TEST_LIBS)
