// SPDX-License-Identifier: MIT
// msgraphs_collab's command line and mission.txt start delays (tools/collab/options.hpp), and
// the hand-written JSON of its --summary (tools/collab/json_writer.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "json_writer.hpp"
#include "options.hpp"
#include "tool_process.hpp"

namespace msgraphs::tools::collab {
namespace {

bool Parse(std::vector<std::string> args, Options& o, std::string& error) {
  args.insert(args.begin(), "msgraphs_collab");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return ParseOptions(static_cast<int>(argv.size()), argv.data(), o, error);
}

TEST(CollabOptions, ThresholdsDelaysAndSummaryAreOptions) {
  Options o;
  std::string error;
  ASSERT_TRUE(Parse({"--run", "/r", "--wrong-origin-m", "0.25", "--wrong-origin-deg", "1.5",
                     "--delay-s", "2=90", "--summary", "/s.json", "--mode", "keyframes",
                     "--until-s", "20.05", "--max-keyframes", "1000", "--timing"},
                    o, error))
      << error;
  EXPECT_EQ(o.evaluation.wrong_origin_m, 0.25);
  EXPECT_EQ(o.evaluation.wrong_origin_deg, 1.5);
  EXPECT_EQ(o.delays_s.at(2), 90.0);
  EXPECT_EQ(o.summary_path, "/s.json");
  EXPECT_TRUE(o.keyframes);
  EXPECT_EQ(o.until_s, 20.05);
  EXPECT_EQ(o.max_keyframes, 1000u);
  EXPECT_TRUE(o.timing);
  // The defaults: 0.5 m and 2 deg, and the whole mission.
  Options d;
  ASSERT_TRUE(Parse({"--run", "/r"}, d, error));
  EXPECT_EQ(d.evaluation.wrong_origin_m, 0.5);
  EXPECT_EQ(d.evaluation.wrong_origin_deg, 2.0);
  EXPECT_EQ(d.until_s, 0.0);
  EXPECT_EQ(d.max_keyframes, 0u);  // the mapper's own
  EXPECT_FALSE(d.timing);
}

TEST(CollabOptions, BadValuesAreRefusedWithAReason) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--run", "/r", "--wrong-origin-m", "-1"},
        {"--run", "/r", "--wrong-origin-deg", "x"},
        {"--run", "/r", "--delay-s", "2"},
        {"--run", "/r", "--exchange-every-s", "0"},
        {"--run", "/r", "--until-s", "0"},
        {"--run", "/r", "--until-s", "nan"},
        {"--run", "/r", "--max-keyframes", "0"},
        {"--run", "/r", "--max-keyframes", "12.5"},
        {"--run", "/r", "--max-keyframes", "-3"},
        {"--run", "/r", "--max-keyframes", "65537"},
        {"--run", "/r", "--max-keyframes"},
        {"--run", "/r", "--mode", "magic"},
        {"--run", "/r", "--summary"},
        {"--wrong-origin-m", "0.5"}}) {
    Options o;
    std::string error;
    EXPECT_FALSE(Parse(args, o, error)) << args.back();
    EXPECT_FALSE(error.empty());
  }
}

TEST(CollabOptions, StartDelaysComeFromMissionTxtAndTheOptionOverrides) {
  const std::string path = test::Temp("mission.txt");
  std::ofstream(path) << "msgraphs-mission 1\nrobots 3\n"
                      << "robot 1 start_room S5 unix_offset_s 1.0 rooms S5 S2\n"
                      << "robot 2 start_room S2 start_delay_s 45.5 rooms S2\n"
                      << "robot 3 start_delay_s 120 start_room N4\n";
  std::map<int, double> from_file;
  std::string error;
  ASSERT_TRUE(ReadStartDelays(path, from_file, error)) << error;
  EXPECT_EQ(from_file.count(1), 0u);  // no key: no delay
  EXPECT_EQ(from_file.at(2), 45.5);
  EXPECT_EQ(from_file.at(3), 120.0);
  const std::map<int, double> option = {{3, 10.0}};
  EXPECT_STREQ(ResolveStartDelay(1, from_file, option).source, "none");
  EXPECT_EQ(ResolveStartDelay(1, from_file, option).delay_s, 0.0);
  EXPECT_STREQ(ResolveStartDelay(2, from_file, option).source, "mission.txt");
  EXPECT_EQ(ResolveStartDelay(2, from_file, option).delay_s, 45.5);
  EXPECT_STREQ(ResolveStartDelay(3, from_file, option).source, "--delay-s");
  EXPECT_EQ(ResolveStartDelay(3, from_file, option).delay_s, 10.0);
  // No file: no delays, no error.
  std::map<int, double> none;
  EXPECT_TRUE(ReadStartDelays(path + ".absent", none, error));
  EXPECT_TRUE(none.empty());
  // A key without a valid value is an error naming the line.
  std::ofstream(path) << "robot 1 start_delay_s -3\n";
  EXPECT_FALSE(ReadStartDelays(path, none, error));
  EXPECT_NE(error.find("mission.txt:1: start_delay_s of robot 1"), std::string::npos) << error;
  std::ofstream(path) << "robot 2 start_delay_s\n";
  EXPECT_FALSE(ReadStartDelays(path, none, error));
  std::filesystem::remove(path);
}

TEST(JsonWriter, NestsEscapesAndWritesNonFiniteNumbersAsNull) {
  JsonWriter json;
  json.BeginObject();
  json.Field("name", "a \"quoted\"\\path\n");
  json.Field("n", 3);
  json.Field("x", 0.5);
  json.Field("nan", std::numeric_limits<double>::quiet_NaN());
  json.Field("none", std::optional<double>{});
  json.Key("list");
  json.BeginArray();
  json.Bool(true);
  json.BeginObject();
  json.EndObject();
  json.BeginArray();
  json.EndArray();
  json.EndArray();
  json.EndObject();
  EXPECT_EQ(json.text(),
            "{\n"
            "  \"name\": \"a \\\"quoted\\\"\\\\path\\n\",\n"
            "  \"n\": 3,\n"
            "  \"x\": 0.5,\n"
            "  \"nan\": null,\n"
            "  \"none\": null,\n"
            "  \"list\": [\n"
            "    true,\n"
            "    {},\n"
            "    []\n"
            "  ]\n"
            "}\n");
}

}  // namespace
}  // namespace msgraphs::tools::collab
