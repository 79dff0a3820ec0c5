// The one settings table (render/settings_table.h): every entry reaches the
// command line (render, bench and view take --NAME), the viewer's script
// (`set NAME VALUE`) and the renderer's validation with the one range and
// the one wording, and its text round-trips.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "app/viewer/viewer_actions.h"
#include "core/error.h"
#include "render/settings_table.h"
#include "test_support.h"

namespace fibscope {
namespace {

// A value just past the entry's range, as text; empty for kinds without one.
std::string pastTheRange(const SettingInfo& info) {
  switch (info.kind) {
    case SettingKind::Integer: return std::to_string(int(info.max) + 1);
    case SettingKind::Number: return std::to_string(info.max + std::max(1.0, info.max));
    case SettingKind::Color: return "0.5,1.5,0";
    case SettingKind::Range: return "5,1";
    case SettingKind::Choice: return "no-such-choice";
    case SettingKind::Flag: return "maybe";
  }
  return {};
}


TEST(SettingsTable, namesAreUniqueAndEveryEntryIsComplete) {
  std::set<std::string> names;
  for (const SettingInfo& info : renderSettingsTable()) {
    SCOPED_TRACE(std::string(info.name));
    EXPECT_TRUE(names.insert(std::string(info.name)).second);
    if (!info.alias.empty()) {
      EXPECT_TRUE(names.insert(std::string(info.alias)).second);
    }
    EXPECT_FALSE(info.label.empty());
    EXPECT_FALSE(info.help.empty());
    EXPECT_EQ(findSetting(info.name), &info);
    if (info.kind == SettingKind::Number || info.kind == SettingKind::Integer) {
      EXPECT_LT(info.min, info.max);
    }
  }
  EXPECT_EQ(findSetting("width"), findSetting("line-width"));
  EXPECT_EQ(findSetting("no-such-setting"), nullptr);
  // The defaults are within the table's ranges.
  EXPECT_NO_THROW(validateRenderSettings(RenderSettings{}));
}

TEST(SettingsTable, everyValueRoundTripsThroughItsText) {
  for (const SettingInfo& info : renderSettingsTable()) {
    SCOPED_TRACE(std::string(info.name));
    RenderSettings a;
    // Another valid value than the default: the range's top, the last
    // choice, a flag flipped, a colour, a range.
    std::string text;
    switch (info.kind) {
      case SettingKind::Flag: text = a.*info.flag ? "off" : "on"; break;
      case SettingKind::Integer: text = std::to_string(int(info.max)); break;
      case SettingKind::Number: text = "0.5"; if (!(0.5 >= info.min && 0.5 <= info.max)) text = std::to_string(info.max); break;
      case SettingKind::Choice: text = std::string(info.choice_name(info.choice_count - 1)); break;
      case SettingKind::Color: text = "0.25,0.5,1"; break;
      case SettingKind::Range: text = "-2.5,7"; break;
    }
    setSetting(a, info, text, "test");
    const std::string back = settingText(a, info);
    RenderSettings b;
    setSetting(b, info, back, "test");
    EXPECT_EQ(settingText(b, info), back);
    EXPECT_NO_THROW(validateRenderSettings(a));
  }
}

TEST(SettingsTable, theScriptAndTheValidationRejectWhatIsOutOfRangeWithTheRange) {
  for (const SettingInfo& info : renderSettingsTable()) {
    SCOPED_TRACE(std::string(info.name));
    const std::string expectation = settingExpectation(info);
    const std::string bad = pastTheRange(info);
    RenderSettings s;
    const std::string before = settingText(s, info);
    const std::string script = test::errorOf([&] { applySetting(s, info.name, bad); });
    EXPECT_NE(script.find("set " + std::string(info.name) + ": expected " + expectation), std::string::npos) << script;
    EXPECT_EQ(settingText(s, info), before) << "a rejected value changed the setting";
    // The renderer's check, on a value the program set without parsing.
    RenderSettings direct;
    switch (info.kind) {
      case SettingKind::Integer: direct.*info.integer = int(info.max) + 1; break;
      case SettingKind::Number: direct.*info.number = float(info.max + std::max(1.0, info.max)); break;
      case SettingKind::Color: (direct.*info.color)[1] = 1.5f; break;
      case SettingKind::Range:
        direct.*info.number = 5;
        direct.*info.number_max = 1;
        break;
      case SettingKind::Choice: info.set_choice(direct, info.choice_count); break;
      case SettingKind::Flag: continue;  // every bool is valid
    }
    const std::string check = test::errorOf([&] { validateRenderSettings(direct); });
    EXPECT_NE(check.find(std::string(info.label) + " must be " + expectation), std::string::npos) << check;
  }
  EXPECT_NE(test::errorOf([] {
              RenderSettings s;
              applySetting(s, "speed", "3");
            }).find("unknown setting 'speed'"),
            std::string::npos);
}

TEST(SettingsTable, theCommandLineTakesEveryEntryWithTheSameRange) {
  const auto help = test::runFibscope("render --help");
  ASSERT_EQ(help.exit_code, 0) << help.output;
  RenderSettings render_defaults;
  render_defaults.orientation_labels = true;  // render's own default (--no-orientation-labels)
  for (const SettingInfo& info : renderSettingsTable()) {
    SCOPED_TRACE(std::string(info.name));
    const bool negated = info.kind == SettingKind::Flag && render_defaults.*info.flag;
    const std::string flag = (negated ? "--no-" : "--") + std::string(info.name);
    EXPECT_NE(help.output.find(flag), std::string::npos) << help.output;
    if (info.kind == SettingKind::Flag) continue;
    // Rejected before any file is read or device made: one line, exit 2,
    // the table's expectation.
    const auto r = test::runFibscope("render --phantom-streamlines 10 " + flag + " '" + pastTheRange(info) +
                                     "' -o /nonexistent/x.png");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(flag + ": expected " + settingExpectation(info)), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace fibscope
