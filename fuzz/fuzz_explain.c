/* fuzz_explain.c - libFuzzer entry point of harness_explain.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_explain(data, size))
        abort();
    return 0;
}
