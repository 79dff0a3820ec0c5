#include "app/viewer/viewer_actions.h"

#include <string>

#include "core/error.h"
#include "render/settings_table.h"

namespace fibscope {

void applySetting(RenderSettings& settings, std::string_view key, std::string_view value) {
  const SettingInfo* info = findSetting(key);
  if (!info) {
    std::string names;
    for (const SettingInfo& i : renderSettingsTable()) names += (names.empty() ? "" : ", ") + std::string(i.name);
    throw Error("set: unknown setting '" + std::string(key) + "' (expected one of: " + names + ")");
  }
  setSetting(settings, *info, value, "set " + std::string(key));
}

ViewAction parseViewName(std::string_view name) {
  if (name == "sagittal") return {StandardView::Sagittal};
  if (name == "coronal") return {StandardView::Coronal};
  if (name == "axial") return {StandardView::Axial};
  if (name == "reset") return {std::nullopt};
  throw Error("view: expected sagittal, coronal, axial or reset, got '" + std::string(name) + "'");
}

}  // namespace fibscope
