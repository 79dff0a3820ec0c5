// Every render setting declared once: its name, the RenderSettings member
// it edits, its range, default (RenderSettings{}'s) and help. The command
// line (app/render_options: one flag per entry), the viewer's script
// (`set NAME VALUE`), the viewer's panel (one widget per entry) and the
// renderer's validation all read this table, so a setting has one name,
// one range and one help text everywhere. Adding a setting: a member in
// RenderSettings, one entry in settings_table.cpp, and its use.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "render/render_settings.h"

namespace fibscope {

enum class SettingKind : uint8_t {
  Flag,     // bool: "on" / "off" (command line: --NAME, or --no-NAME when on by default)
  Integer,  // int in [min, max]
  Number,   // float in [min, max] (finite)
  Choice,   // one of `choice_count` names
  Color,    // R,G,B each in [0, 1]
  Range,    // MIN,MAX, finite, MIN <= MAX (two floats), each in [min, max]
};

struct SettingInfo {
  std::string_view name;   // "ssao-radius": --ssao-radius, `set ssao-radius 12`
  std::string_view label;  // the panel's label
  std::string_view help;   // the command line's help and the panel's tooltip
  SettingKind kind = SettingKind::Number;
  double min = 0, max = 0;     // Integer, Number, Range (inclusive)
  std::string_view unit;       // "px", "mm" or empty: in messages and the panel's format
  std::string_view alias;      // an older script name ("width"), or empty
  // The member (one of these, by kind).
  bool RenderSettings::*flag = nullptr;
  int RenderSettings::*integer = nullptr;
  float RenderSettings::*number = nullptr;  // Number; Range's MIN
  float RenderSettings::*number_max = nullptr;  // Range's MAX
  std::array<float, 3> RenderSettings::*color = nullptr;
  // Choice: names 0 .. choice_count - 1 (the enum's order) and the member.
  int choice_count = 0;
  std::string_view (*choice_name)(int) = nullptr;
  int (*get_choice)(const RenderSettings&) = nullptr;
  void (*set_choice)(RenderSettings&, int) = nullptr;
  // The panel shows the setting only when this holds (null: always), e.g.
  // the colormap only with ColorMode::Scalar.
  bool (*relevant)(const RenderSettings&) = nullptr;
  // The viewer panel that shows it: empty for the render settings panel,
  // "anatomy" for the anatomy panel (whose slice sliders span the loaded
  // volume rather than the table's range).
  std::string_view group;
};

// The table, in the panel's order.
std::span<const SettingInfo> renderSettingsTable();
// The entry named `name` (or whose alias it is); null when none.
const SettingInfo* findSetting(std::string_view name);

// Sets the entry's member from text as the command line and the script
// write it. Throws Error "WHERE: expected ..., got 'TEXT'" (one line, the
// range and unit included); leaves `settings` unchanged then. Safe on
// untrusted text.
void setSetting(RenderSettings& settings, const SettingInfo& info, std::string_view text, std::string_view where);
// The member as such text ("on", "12.5", "two-phase", "0.1,0.2,0.3").
std::string settingText(const RenderSettings& settings, const SettingInfo& info);
// "1 to 64 px", "on or off", "one of: none, frustum, two-phase, coverage", ...
std::string settingExpectation(const SettingInfo& info);

// Every entry's member within its range (a choice within its names, a
// range with MIN <= MAX). Throws Error "render: LABEL must be EXPECTATION,
// got VALUE" for the first that is not.
void validateRenderSettings(const RenderSettings& settings);

}  // namespace fibscope
