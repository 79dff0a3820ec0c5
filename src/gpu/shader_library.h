// The SPIR-V of every shaders/*.{comp,vert,frag,geom,tesc,tese}, compiled by
// glslc at build time and embedded in the library (cmake/embed_spirv.cmake),
// so no shader file has to be found at run time.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace fibscope::gpu {

struct EmbeddedShader {
  const char* name;  // the source file name, e.g. "fiblet_decode_test.comp"
  std::span<const uint32_t> words;
};

// Defined in the generated build/gpu/embedded_shaders.cpp.
std::span<const EmbeddedShader> embeddedShaders();

// The SPIR-V words of shader `name` (the source file name). Throws Error
// naming the shader when there is none of that name.
std::span<const uint32_t> shaderWords(std::string_view name);

}  // namespace fibscope::gpu
