// Push constants of shaders/dataset_decode_test.comp: the dataset block's
// address and the test's outputs. Everything about the fiblets comes
// through the block (shared/fiblet_dataset.h).
#ifndef FIBSCOPE_SHADERS_SHARED_DATASET_DECODE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_DATASET_DECODE_PUSH_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

struct DatasetDecodePush {
  uint64_t dataset;  // FibletDataset (one struct)
  uint64_t points;   // float[3 * N] per fiblet: the decoded normalised points
  uint64_t counts;   // uint per fiblet: decoded point count (0: invalid record)
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::DatasetDecodePush) == 24, "push constants are 24 bytes in std430");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_DATASET_DECODE_PUSH_H
