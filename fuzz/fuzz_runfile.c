/* fuzz_runfile.c - libFuzzer entry point of harness_runfile.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_runfile(data, size))
        abort();
    return 0;
}
