/* fuzz_capi.c - libFuzzer entry point of harness_capi.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_capi(data, size))
        abort();
    return 0;
}
