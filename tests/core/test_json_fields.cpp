// The field checks every JSON loader uses (core/json_file.h): a file field breaks a rule with the
// message of the flag of the same quantity, naming the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/json_file.h"
#include "support/expect_error.h"
#include "support/scratch_dir.h"

namespace whirl {
namespace {

using nlohmann::json;

TEST(JsonFields, NumberInRangeNamesFileKeyValueAndRange) {
  const Range r{0, 1, false, "K"};
  const json j = json::parse(R"({"spread": 1e308, "ok": 0.5, "neg": -1e-300, "s": "1"})");
  EXPECT_EQ(RequireNumberIn(j, "ok", r, "f.json"), 0.5);
  EXPECT_EQ(ErrorOf([&] { RequireNumberIn(j, "spread", r, "machine file 'f.json'"); }),
            "machine file 'f.json': spread = 1e+308 breaks the rule: must lie in [0, 1] K");
  EXPECT_NE(ErrorOf([&] { RequireNumberIn(j, "neg", r, "f"); }).find("neg = -1e-300"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { RequireNumberIn(j, "s", r, "f"); }).find("'s' must be a number"),
            std::string::npos);
  const Range open{0, 5, true, "mm"};
  EXPECT_NE(ErrorOf([&] {
              RequireNumberIn(json{{"x", 0}}, "x", open, "f");
            }).find("(0, 5] mm"),
            std::string::npos);
  double v = 7;
  OptionalNumberIn(j, "absent", r, v, "f");
  EXPECT_EQ(v, 7) << "an absent key keeps the default";
  EXPECT_THROW(OptionalNumberIn(j, "spread", r, v, "f"), InputError);
}

TEST(JsonFields, IntegerRefusesStringsFractionsAndRange) {
  const json j = json::parse(R"({"a": 3, "b": 3.0, "c": 1.5, "d": "3", "e": 1e308, "f": -1})");
  EXPECT_EQ(RequireInteger(j, "a", 1, 5, "f"), 3);
  EXPECT_EQ(RequireInteger(j, "b", 1, 5, "f"), 3);
  for (const char* key : {"c", "d", "e", "f"})
    EXPECT_NE(ErrorOf([&] {
                RequireInteger(j, key, 1, 5, "f.json");
              }).find(std::string("f.json: '") + key + "' = "),
              std::string::npos)
        << key;
  EXPECT_NE(ErrorOf([&] { RequireInteger(j, "zz", 1, 5, "f.json"); }).find("missing"),
            std::string::npos);
}

TEST(JsonFields, SchemaAndVersion) {
  const std::string w = "machine file 'm.json'";
  EXPECT_NO_THROW(RequireSchema(json::parse(R"({"schema": "x", "schema_version": 1})"), "x", 1, w));
  for (const char* bad :
       {R"({})", R"({"schema": "x"})", R"({"schema": "y", "schema_version": 1})",
        R"({"schema": "x", "schema_version": 99})", R"({"schema": "x", "schema_version": "1"})",
        R"({"schema": "x", "schema_version": 1.5})", R"([1])"}) {
    const std::string e = ErrorOf([&] { RequireSchema(json::parse(bad), "x", 1, w); });
    EXPECT_EQ(e.rfind(w, 0), 0u) << bad << ": " << e;
  }
  EXPECT_NE(ErrorOf([&] {
              RequireSchema(json::parse(R"({"schema": "x", "schema_version": 99})"), "x", 1, w);
            }).find("'schema_version' = 99"),
            std::string::npos);
  EXPECT_NO_THROW(
      RequireSchema(json::parse(R"({"format": "f", "schema_version": 1})"), "f", 1, w, "format"));
}

TEST(JsonFields, StringsAndEnums) {
  const json j = json::parse(R"({"m": "cubic", "n": 3, "long": "abcdef"})");
  EXPECT_EQ(RequireOneOf(j, "m", {"cubic", "bspline"}, "f"), "cubic");
  EXPECT_NE(ErrorOf([&] {
              RequireOneOf(j, "m", {"a", "b"}, "f");
            }).find("one of a, b"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { RequireString(j, "n", "f"); }).find("'n' must be a string"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { RequireString(j, "long", "f", 3); }).find("limit is 3"),
            std::string::npos);
}

// Invalid UTF-8 never escapes as a raw nlohmann exception: in a file it is an InputError naming
// the file; in a string bound for output (a file name) it is replaced.
TEST(JsonFields, InvalidUtf8) {
  const auto path = whirl::test::ScratchDir() / "whirl_test_json_utf8.json";
  std::ofstream(path, std::ios::binary) << "{\"name\": \"a\xFF\"}";
  const std::string e = ErrorOf([&] { ReadJsonFile(path); });
  EXPECT_NE(e.find(path.string()), std::string::npos) << e;
  EXPECT_NE(e.find("line 1, column 12"), std::string::npos) << e;
  EXPECT_NE(e.find("UTF-8"), std::string::npos) << e;
  EXPECT_EQ(e.find("[json.exception"), std::string::npos) << e;
  std::ofstream(path, std::ios::binary) << "\xEF\xBB\xBF{\"name\": \"\xC2\xB5m\"}";
  EXPECT_EQ(ReadJsonFile(path).at("name"), "\xC2\xB5m") << "a byte-order mark is skipped";
  std::filesystem::remove(path);
  const json j = {{"file", std::string("run\xFF.csv")}};
  EXPECT_EQ(DumpJson(j, -1), "{\"file\":\"run\xEF\xBF\xBD.csv\"}");
}

// The value-level checks (array elements, values looked up already): the message names the
// element, the rule and what was there; a whole number is checked before any cast.
TEST(JsonFields, ArraysAndWholeValues) {
  const json j = json::parse(R"({"v": [1, 2.5, -3], "bad": [1, "x"], "s": "1", "n": 7})");
  EXPECT_EQ(RequireNumbers(j.at("v"), "f: 'v'"), (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(ErrorOf([&] { RequireNumbers(j.at("bad"), "f: 'bad'"); }),
            "f: 'bad'[1] must be a number, got \"x\"");
  EXPECT_EQ(ErrorOf([&] { RequireNumbers(j.at("s"), "f: 's'"); }),
            "f: 's' must be an array of numbers, got \"1\"");
  EXPECT_EQ(RequireWholeValue(j.at("n"), "f: 'n'", 0, 10), 7);
  for (const char* bad : {"7.5", "1e30", "-1", "\"7\""})
    EXPECT_NE(ErrorOf([&] { RequireWholeValue(json::parse(bad), "f: 'n'", 0, 10); })
                  .find("f: 'n' must"),
              std::string::npos)
        << bad;
  EXPECT_EQ(ErrorOf([&] { RequireKey(j, "zz", "f"); }), "f: missing required key 'zz'");
  EXPECT_EQ(ErrorOf([&] { RequireKey(json::array(), "zz", "f"); }), "f: expected a JSON object");
}

// Issue 45 item 7: a key given twice in one object (JSON allows it; nlohmann keeps the last) is
// refused, with its path, at every depth; the same key in different objects is fine.
TEST(JsonFields, AKeyGivenTwiceInOneObjectIsRefusedWithItsPath) {
  const auto path = whirl::test::ScratchDir() / "whirl_test_duplicate_keys.json";
  const auto read = [&](const std::string& text) {
    std::ofstream(path, std::ios::trunc) << text;
    return ErrorOf([&] { ReadJsonFile(path); });
  };
  EXPECT_EQ(read(R"({"a": {"b": 1}, "c": [{"b": 2}, {"b": 3}]})"), "") << "no duplicate";
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {R"({"md32760": 0.01, "md32760": 0.1})", "'md32760'"},
           {R"({"drift": {"analog_inputs": {"t3_C": {"index": 3, "index": 4}}}})",
            "'drift.analog_inputs.t3_C.index'"},
           {R"({"runs": [{"name": "a"}, {"name": "b", "x": 1, "name": "c"}]})",
            "'runs[1].name'"},
           {R"([[1], {"k": 1, "k": 1}])", "'[1].k'"}}) {
    const std::string e = read(text);
    EXPECT_NE(e.find(key), std::string::npos) << text << "\n" << e;
    EXPECT_NE(e.find("given twice"), std::string::npos) << e;
    EXPECT_NE(e.find(path.string()), std::string::npos) << e;
  }
}

// Array readers name the key and the element that breaks the rule (no library message).
TEST(JsonFields, ArraysOfStringsNumbersAndWholeNumbersNameKeyAndElement) {
  const json j = json::parse(R"({"s": ["a", 5], "n": [1, "x"], "w": [1, 2.5], "o": 3})");
  EXPECT_EQ(ErrorOf([&] { RequireStrings(j, "s", "model"); }),
            "model: 's'[1] must be a string, got 5");
  EXPECT_EQ(ErrorOf([&] { RequireNumberArray(j, "n", "model"); }),
            "model: 'n'[1] must be a number, got \"x\"");
  EXPECT_NE(ErrorOf([&] { RequireIntegers(j, "w", 0, 9, "model"); }).find("'w'[1] must be a whole"),
            std::string::npos);
  EXPECT_EQ(ErrorOf([&] { RequireObject(j, "o", "model"); }),
            "model: 'o' must be a JSON object, got 3");
  EXPECT_NE(ErrorOf([&] { RequireStrings(j, "o", "model"); }).find("'o' must be an array"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { RequireArray(j, "s", "model", 1); }).find("limit is 1"),
            std::string::npos);
  const json big = {{"v", std::string(500, 'x')}};
  EXPECT_LT(ErrorOf([&] { RequireNumber(big, "v", "model"); }).size(), 120u)
      << "a long value is cut in the message";
}

}  // namespace
}  // namespace whirl
