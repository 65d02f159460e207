/* fuzz_plan.c - libFuzzer entry point of harness_plan.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_plan(data, size))
        abort();
    return 0;
}
