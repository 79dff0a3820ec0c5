// Placeholder until the vtk reader lands (replaced by the real reader).
#include "core/error.h"
#include "io/reader.h"
namespace fibscope {
std::unique_ptr<TractogramReader> openVtk(const std::string& path) { fail(path, "vtk reader not built yet"); }
}  // namespace fibscope
