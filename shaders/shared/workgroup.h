// The workgroup size of a compute shader as specialisation constants, so
// that the C++ which dispatches a pass and the shader take it from the one
// constant in shared/render_config.h (gpu::createComputePipeline with a
// gpu::WorkgroupSize sets them). A shader declares
//   layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;
// Ids far above a pass's own constants (which count from 0).
#ifndef FIBSCOPE_SHADERS_SHARED_WORKGROUP_H
#define FIBSCOPE_SHADERS_SHARED_WORKGROUP_H

#define WORKGROUP_SIZE_X_ID 100
#define WORKGROUP_SIZE_Y_ID 101
#define WORKGROUP_SIZE_Z_ID 102

#endif  // FIBSCOPE_SHADERS_SHARED_WORKGROUP_H
