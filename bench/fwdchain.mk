# The forward model's time per call as throughput and as latency
# (bench/fwd_latency.c; docs/performance.md, "Round 7: the forward's chain").
# A timing, not part of make bench or make test.
$(BN)/pmbench_fwd_latency: bench/fwd_latency.c bench/bench_common.c $(BN)/host/naive.o \
                           $(BENCH_SRC_H) $(B)/libpm.a
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) bench/fwd_latency.c bench/bench_common.c $(BN)/host/naive.o \
	  $(B)/libpm.a -lm -o $@
