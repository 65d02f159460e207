/* fuzz_fit.c - libFuzzer entry point of harness_fit.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_fit(data, size))
        abort();
    return 0;
}
