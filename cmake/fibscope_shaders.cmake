# Vulkan and the SPIR-V build step.
#
# Every shaders/*.comp|vert|frag|geom|tesc|tese|task|mesh is compiled by glslc (Vulkan
# 1.3, -I shaders so that `#include "shared/fiblet.h"` resolves) into
# build/shaders/<name>.spv, with glslc's depfile so that editing an included
# header recompiles the shaders that include it. All .spv are then embedded
# into one generated C++ file (gpu/embedded_shaders.cpp) linked into
# fibscope_gpu, so that the executable, the tests and the sanitizer build find
# their shaders without install steps or paths.

find_package(Vulkan QUIET COMPONENTS glslc)
if(NOT Vulkan_FOUND)
  message(FATAL_ERROR "Vulkan headers and loader not found: install the Debian package libvulkan-dev")
endif()
if(NOT Vulkan_GLSLC_EXECUTABLE)
  message(FATAL_ERROR "glslc (GLSL to SPIR-V compiler) not found: install the Debian package glslc")
endif()

# Run-time pieces that the GPU tests need: the validation layer is required
# (every GPU test runs with it), a driver only warned about (without one the
# GPU tests skip with the reason, as on a machine whose GPU is elsewhere).
if(FIBSCOPE_TESTS)
  find_file(FIBSCOPE_VALIDATION_LAYER_JSON VkLayer_khronos_validation.json
    PATHS /usr/share/vulkan/explicit_layer.d /usr/local/share/vulkan/explicit_layer.d /etc/vulkan/explicit_layer.d
    NO_DEFAULT_PATH)
  if(NOT FIBSCOPE_VALIDATION_LAYER_JSON)
    message(FATAL_ERROR "Vulkan validation layer not found (the GPU tests run with it): install the Debian package vulkan-validationlayers")
  endif()
  file(GLOB FIBSCOPE_VULKAN_ICDS /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json)
  if(NOT FIBSCOPE_VULKAN_ICDS)
    message(WARNING "no Vulkan driver installed: the GPU tests will be skipped (install the Debian package mesa-vulkan-drivers for lavapipe)")
  endif()
endif()

file(GLOB FIBSCOPE_SHADER_SOURCES CONFIGURE_DEPENDS
  ${CMAKE_SOURCE_DIR}/shaders/*.comp ${CMAKE_SOURCE_DIR}/shaders/*.vert ${CMAKE_SOURCE_DIR}/shaders/*.frag
  ${CMAKE_SOURCE_DIR}/shaders/*.geom ${CMAKE_SOURCE_DIR}/shaders/*.tesc ${CMAKE_SOURCE_DIR}/shaders/*.tese
  ${CMAKE_SOURCE_DIR}/shaders/*.task ${CMAKE_SOURCE_DIR}/shaders/*.mesh)
set(FIBSCOPE_SHADER_DIR ${CMAKE_BINARY_DIR}/shaders)
file(MAKE_DIRECTORY ${FIBSCOPE_SHADER_DIR})

# The mesh-shader stages (VK_EXT_mesh_shader) cannot run on every machine
# that builds them (lavapipe has none), so spirv-val checks their SPIR-V
# against Vulkan 1.3's rules at build time, where a broken module would
# otherwise first show on a GPU with mesh shaders.
find_program(FIBSCOPE_SPIRV_VAL spirv-val)
if(NOT FIBSCOPE_SPIRV_VAL)
  message(STATUS "spirv-val not found: the task and mesh shaders' SPIR-V is not validated at build time (install spirv-tools)")
endif()

set(FIBSCOPE_SPIRV_FILES "")
foreach(source ${FIBSCOPE_SHADER_SOURCES})
  get_filename_component(name ${source} NAME)
  get_filename_component(stage ${source} LAST_EXT)
  set(spv ${FIBSCOPE_SHADER_DIR}/${name}.spv)
  set(validate "")
  if(FIBSCOPE_SPIRV_VAL AND (stage STREQUAL ".task" OR stage STREQUAL ".mesh"))
    set(validate COMMAND ${FIBSCOPE_SPIRV_VAL} --target-env vulkan1.3 ${spv})
  endif()
  add_custom_command(
    OUTPUT ${spv}
    COMMAND ${Vulkan_GLSLC_EXECUTABLE} --target-env=vulkan1.3 -O -Werror
            -I ${CMAKE_SOURCE_DIR}/shaders -MD -MF ${spv}.d -o ${spv} ${source}
    ${validate}
    DEPENDS ${source}
    DEPFILE ${spv}.d
    COMMENT "glslc ${name}"
    VERBATIM)
  list(APPEND FIBSCOPE_SPIRV_FILES ${spv})
endforeach()

set(FIBSCOPE_EMBEDDED_SHADERS ${CMAKE_BINARY_DIR}/gpu/embedded_shaders.cpp)
add_custom_command(
  OUTPUT ${FIBSCOPE_EMBEDDED_SHADERS}
  COMMAND ${CMAKE_COMMAND} -DOUTPUT=${FIBSCOPE_EMBEDDED_SHADERS} "-DINPUTS=${FIBSCOPE_SPIRV_FILES}"
          -P ${CMAKE_SOURCE_DIR}/cmake/embed_spirv.cmake
  DEPENDS ${FIBSCOPE_SPIRV_FILES} ${CMAKE_SOURCE_DIR}/cmake/embed_spirv.cmake
  COMMENT "embedding SPIR-V"
  VERBATIM)
