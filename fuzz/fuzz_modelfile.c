/* fuzz_modelfile.c - libFuzzer entry point of harness_modelfile.c. */
#include <stdint.h>
#include <stdlib.h>
#include "harness.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (pmfz_modelfile(data, size))
        abort();
    return 0;
}
