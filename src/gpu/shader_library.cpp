#include "gpu/shader_library.h"

#include <string>

#include "core/error.h"

namespace fibscope::gpu {

std::span<const uint32_t> shaderWords(std::string_view name) {
  for (const EmbeddedShader& shader : embeddedShaders())
    if (name == shader.name) return shader.words;
  throw Error("vulkan: no shader named " + std::string(name) + " was built (shaders/" + std::string(name) +
              " missing when cmake last ran?)");
}

}  // namespace fibscope::gpu
