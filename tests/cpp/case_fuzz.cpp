// The C++ case reader (io/case.hpp) cannot be made to crash, hang or throw anything but ConfigError.
// A deterministic corpus of mutations of the built-in case files (each with a [control] table of
// every kind appended): truncations, byte flips, erased and duplicated slices, inserted TOML
// markup, values replaced by values of the wrong type or by huge numbers, deep nesting. Each
// document either loads (a model with physical bodies, its [control] checked against it, and the
// controller it describes built or refused with std::invalid_argument) or gives a one-line
// ConfigError naming a field. `make test-sanitize` runs this corpus under AddressSanitizer and
// UndefinedBehaviorSanitizer, like the URDF reader's (test_parser_fuzz.cpp); its own executable
// (mechbal_case_fuzz). To find the document behind an abort (a failed assertion in a library, a
// sanitizer report), set MECHBAL_CASE_FUZZ_DUMP to a file path: each document is written there,
// with its mutation number on the first line, before it is read, so the file holds the last one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "mechbal/algorithm/center_of_mass.hpp"
#include "mechbal/control/factory.hpp"
#include "mechbal/io/case.hpp"
#include "mechbal/model/data.hpp"
#include "mechbal/model/rigid_body.hpp"

using namespace mechbal;

namespace {

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Every built-in TOML file of the package with a [mechanism] table the reader loads.
std::vector<std::string> seed_documents() {
  std::vector<std::filesystem::path> paths;
  for (const auto& e : std::filesystem::recursive_directory_iterator(MECHBAL_SOURCE_DIR "/python/mechbal")) {
    if (e.is_regular_file() && e.path().extension() == ".toml") paths.push_back(e.path());
  }
  std::sort(paths.begin(), paths.end());  // a deterministic corpus whatever the directory order
  std::vector<std::string> seeds;
  for (const auto& p : paths) {
    const std::string text = read(p);
    if (text.find("[mechanism]") == std::string::npos) continue;
    try {
      case_from_string(text, p.string());
      seeds.push_back(text);
    } catch (const ConfigError&) {
      // not a loadable case on its own (a sweep file, a fragment): not a seed
    }
  }
  return seeds;
}

/// A [control] table of each kind for a model with `na` actuated joints, the first named `joint`.
std::string control_table(int which, int na, const std::string& joint) {
  auto list = [na](const char* value) {
    std::string s = "[";
    for (int i = 0; i < na; ++i) s += (i ? ", " : "") + std::string(value);
    return s + "]";
  };
  switch (which % 4) {
    case 0: return "";
    case 1: return "\n[control]\nkind = \"computed_torque\"\nrate_hz = 500\nkp = " + list("100.0") + "\nkd = " + list("20") + "\n";
    case 2: return "\n[control]\nkind = \"decoupled\"\nkp = " + list("100.0") + "\nkd = " + list("20.0") + "\nk = " + list("1.5") + "\n";
    default:
      return "\n[control]\nkind = \"reactionless\"\nbalancing_joints = [\"" + joint +
             "\"]\ncancel = [\"moment\", \"force_z\"]\nintegrator = \"euler\"\ndamping = 0.01\nmax_rate = 50\n"
             "home_gain = 0.5\nlimit_gain = 0.1\nkp = " + list("400.0") + "\nkd = " + list("40.0") + "\ntorque_limit = " +
             list("1e3") + "\n";
  }
}

const std::vector<std::string> kInsertions = {
    "[", "]", "[[", "]]", "{", "}", "=", " = ", ",", "\"", "'''", "\"\"\"", "#", "\n", ".", "-", "+",
    "[mechanism]\n", "[[mechanism.joints]]\n", "[[mechanism.loops]]\n", "[control]\n", "[trajectory]\n",
    "name = \"x\"\n", "kind = \"reactionless\"\n", "type = \"spherical\"\n", "mimic = { joint = \"x\" }\n",
    "nan", "inf", "-inf", "1e999", "1e308", "-1e308", "9223372036854775807", "9223372036854775808",
    "0x7fffffff", "1979-05-27T07:32:00Z", "true", "\"\"", "[]", "{}", std::string(1, '\0'), "\xff\xfe",
    "\xc3\x28", "\\u0000", "a.b.c = 1\n",
};

/// Values of every wrong type and size: what replaces the value of a `key = value` line.
const std::vector<std::string> kValues = {
    "\"x\"", "\"\"", "1", "-1", "0", "0.0", "-0.0", "1e12", "1e13", "-1e300", "1e308", "5e-324",
    "nan", "-inf", "true", "[]", "[1]", "[1, 2]", "[1, 2, 3]", "[\"a\", \"b\"]", "[[1, 2, 3], [4, 5, 6], [7, 8, 9]]",
    "[1, \"a\", true]", "{}", "{ xyz = [0, 0, 0] }", "{ a = { b = 1 } }", "1979-05-27", "07:32:00",
    "9223372036854775807", "-9223372036854775808", std::string(300, '9'), "\"" + std::string(200, 'w') + "\"",
};

/// The position after a random "= " of `doc` and the end of its line (npos, npos when none).
std::pair<std::size_t, std::size_t> random_value(std::mt19937& rng, const std::string& doc) {
  std::vector<std::size_t> at;
  for (std::size_t i = doc.find(" = "); i != std::string::npos; i = doc.find(" = ", i + 1)) at.push_back(i + 3);
  if (at.empty()) return {std::string::npos, std::string::npos};
  const std::size_t start = at[std::uniform_int_distribution<std::size_t>(0, at.size() - 1)(rng)];
  const std::size_t end = doc.find('\n', start);
  return {start, end == std::string::npos ? doc.size() : end};
}

std::string nested(int depth, bool tables) {
  std::string s = "x = ";
  for (int i = 0; i < depth; ++i) s += tables ? "{ a = " : "[";
  s += "1";
  for (int i = 0; i < depth; ++i) s += tables ? " }" : "]";
  return s + "\n";
}

std::string mutate(std::mt19937& rng, std::string doc) {
  std::uniform_int_distribution<int> op(0, 7), count(1, 3);
  for (int k = count(rng); k > 0 && !doc.empty(); --k) {
    std::uniform_int_distribution<std::size_t> at(0, doc.size() - 1);
    const std::size_t i = at(rng);
    switch (op(rng)) {
      case 0: doc[i] = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng)); break;
      case 1: doc.erase(i, std::uniform_int_distribution<std::size_t>(1, 60)(rng)); break;
      case 2: doc.resize(i); break;
      case 3: doc.insert(i, kInsertions[std::uniform_int_distribution<std::size_t>(0, kInsertions.size() - 1)(rng)]); break;
      case 4: {  // duplicate a slice (repeated tables, keys and names)
        const std::size_t n = std::uniform_int_distribution<std::size_t>(1, 300)(rng);
        doc.insert(at(rng), doc.substr(i, n));
        break;
      }
      case 5:
      case 6: {  // a value of the wrong type, size or magnitude
        const auto [start, end] = random_value(rng, doc);
        if (start != std::string::npos)
          doc.replace(start, end - start, kValues[std::uniform_int_distribution<std::size_t>(0, kValues.size() - 1)(rng)]);
        break;
      }
      default: {  // deep nesting, as a value of a key or in place of one
        const int depth = std::vector<int>{8, 33, 64, 300, 5000}[std::uniform_int_distribution<std::size_t>(0, 4)(rng)];
        const std::string text = nested(depth, std::uniform_int_distribution<int>(0, 1)(rng) == 1);
        const auto [start, end] = random_value(rng, doc);
        if (start != std::string::npos && std::uniform_int_distribution<int>(0, 1)(rng)) {
          doc.replace(start, end - start, text.substr(4, text.size() - 5));
        } else {
          doc.insert(doc.rfind('\n', i) == std::string::npos ? 0 : doc.rfind('\n', i) + 1, text);
        }
      }
    }
  }
  return doc;
}

struct Outcome {
  int loaded = 0, refused = 0, controllers = 0, controllers_refused = 0, other = 0;
};

/// Loads or gives a one-line ConfigError naming a field; nothing else.
void check(const std::string& doc, Outcome& out) {
  try {
    const LoadedCase c = case_from_string(doc, "fuzz.toml");
    for (const Body& b : c.model.bodies()) {
      EXPECT_NO_THROW(validate_rigid_body(RigidBody{b.mass, b.inertia}, "fuzz")) << b.name;
      EXPECT_TRUE(b.com.allFinite()) << b.name;
    }
    MechanismData data(c.model);
    EXPECT_EQ(center_of_mass(c.model, data, Eigen::VectorXd::Zero(c.model.dof())), Status::ok);
    ++out.loaded;
    if (c.control.kind == ControlKind::none) return;
    try {  // the controller it describes: built, or refused at construction naming a field
      const Eigen::VectorXd guess =
          c.trajectory.initial_guess.empty()
              ? Eigen::VectorXd()
              : Eigen::Map<const Eigen::VectorXd>(c.trajectory.initial_guess.data(), c.model.dof());
      const Eigen::VectorXd q0 = c.trajectory.start.empty()
                                     ? Eigen::VectorXd()
                                     : Eigen::Map<const Eigen::VectorXd>(c.trajectory.start.data(), c.model.num_actuated());
      auto controller = make_controller(c.model, c.control, guess, q0);
      EXPECT_EQ(controller->dof(), c.model.num_actuated());
      ++out.controllers;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      ++out.controllers_refused;
    }
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_FALSE(what.empty());
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind(e.field(), 0), 0u) << what;
    ++out.refused;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a ConfigError: " << e.what() << "\n--- document ---\n" << doc.substr(0, 2000);
    ++out.other;
  }
}

std::vector<std::string> first_joint_names(const std::vector<std::string>& seeds, std::vector<int>& actuated) {
  std::vector<std::string> names;
  for (const auto& s : seeds) {
    const LoadedCase c = case_from_string(s);
    actuated.push_back(c.model.num_actuated());
    names.push_back(c.model.coordinate_name(c.model.actuated_coordinates().back()));
  }
  return names;
}

}  // namespace

TEST(CaseFuzz, TheSeedsAreTheBuiltInCases) {
  const auto seeds = seed_documents();
  // the general built-in cases (six), and the papers' while their folders are there
  const bool papers = std::filesystem::exists(MECHBAL_SOURCE_DIR "/python/mechbal/papers/paminsa/cases");
  EXPECT_GE(seeds.size(), papers ? 8u : 6u);
  std::vector<int> actuated;
  const auto names = first_joint_names(seeds, actuated);
  // each seed with each kind of [control] loads
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    for (int which = 0; which < 4; ++which) {
      std::string doc = seeds[s];
      if (doc.find("\n[control]") != std::string::npos) doc = doc.substr(0, doc.find("\n[control]"));
      const std::string table = control_table(which, actuated[s], names[s]);
      if (which % 4 == 3 && actuated[s] == 1) {
        // the joint mode balancing the only actuated joint leaves none to follow [trajectory]: refused
        EXPECT_THROW(case_from_string(doc + table), ConfigError) << s;
      } else {
        EXPECT_NO_THROW(case_from_string(doc + table)) << s << " " << which;
      }
    }
  }
}

TEST(CaseFuzz, DeterministicMutationCorpus) {
  const auto seeds = seed_documents();
  ASSERT_FALSE(seeds.empty());
  std::vector<int> actuated;
  const auto names = first_joint_names(seeds, actuated);
  std::mt19937 rng(27);
  Outcome out;
  const int mutations = 6000;
  const char* dump = std::getenv("MECHBAL_CASE_FUZZ_DUMP");
  for (int i = 0; i < mutations; ++i) {
    const std::size_t s = static_cast<std::size_t>(i) % seeds.size();
    std::string doc = seeds[s];
    if (doc.find("\n[control]") != std::string::npos) doc = doc.substr(0, doc.find("\n[control]"));
    doc += control_table(i / static_cast<int>(seeds.size()), actuated[s], names[s]);
    doc = mutate(rng, doc);
    if (dump) std::ofstream(dump, std::ios::binary | std::ios::trunc) << "# mutation " << i << "\n" << doc;
    check(doc, out);
  }
  std::printf("case reader fuzz: %d documents: %d loaded (%d controllers built, %d refused), %d refused, %d other\n",
              mutations, out.loaded, out.controllers, out.controllers_refused, out.refused, out.other);
  EXPECT_EQ(out.other, 0);
  // the corpus reaches every outcome (one that only produced errors would prove little)
  EXPECT_GT(out.loaded, 300);
  EXPECT_GT(out.refused, 1500);
  EXPECT_GT(out.controllers, 50);
}

TEST(CaseFuzz, DeepNestingIsAConfigError) {
  const std::string base = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/reaction-wheel-arm.toml");
  for (const int depth : {33, 300, 100000}) {
    for (const bool tables : {false, true}) {
      Outcome out;
      check(nested(depth, tables) + base, out);
      EXPECT_EQ(out.refused, 1) << depth << (tables ? " tables" : " arrays");
      try {
        case_from_string(nested(depth, tables) + base, "deep.toml");
      } catch (const ConfigError& e) {
        EXPECT_EQ(e.field(), "deep.toml") << e.what();
        EXPECT_NE(std::string(e.what()).find("too deeply"), std::string::npos) << e.what();
      }
    }
  }
  // dotted keys and table headers nest tables too (toml++ walks them recursively: a stack
  // overflow at ~1e5 levels before the reader refused them ahead of parsing)
  for (const int depth : {33, 1000, 100000}) {
    std::string key;
    for (int i = 0; i < depth; ++i) key += "x.";
    for (const std::string& doc : {key + "y = 1\n" + base, "[" + key + "y]\nz = 1\n" + base,
                                   base + "\n[[" + key + "y]]\n", base + "\n[mechanism]\n" + key + "y = 1\n"}) {
      try {
        case_from_string(doc, "deep.toml");
        ADD_FAILURE() << depth;
      } catch (const ConfigError& e) {
        EXPECT_EQ(e.field(), "deep.toml") << e.what();
        EXPECT_NE(std::string(e.what()).find("too deeply"), std::string::npos) << e.what();
      }
    }
  }
  // a little nesting is fine: the case loads ([balance] is left to its own reader)
  Outcome out;
  check(base + "\n[balance]\n" + nested(20, false), out);
  check(base + "\n[balance]\na.b.c.d.e.f = 1.5\n", out);
  EXPECT_EQ(out.loaded, 2);
}

TEST(CaseFuzz, FilesThatAreNotCases) {
  for (const std::string path : {std::string("/nonexistent/case.toml"), std::string(MECHBAL_SOURCE_DIR "/python")}) {
    try {
      load_case(path);
      ADD_FAILURE() << path;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.field(), "case") << e.what();
    }
  }
}

// Three kinds of text on which toml++ 3.3.0 breaks an assumption of its own (an abort in a debug
// build, undefined behaviour in a release build), each found by the mutation corpus above: a table
// header whose `[` or `[[` is followed by a character that starts no key (parse_key asserts; fixed
// upstream after 3.4.0, marzer/tomlplusplus#301), a `}` where an array expects a value
// (parse_value asserts), a character that is not ASCII outside strings and comments
// (is_horizontal_whitespace reaches __builtin_unreachable; fixed upstream after 3.4.0,
// marzer/tomlplusplus#305). The reader refuses them before toml++ reads them, with the line and
// column of that character, or at toml++'s own error when one comes before.
namespace {

std::string refusal(const std::string& doc) {
  try {
    case_from_string(doc, "header.toml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "header.toml") << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted:\n" << doc;
  return "";
}

}  // namespace

TEST(CaseFuzz, TableHeaderWithoutAKey) {
  const std::string base = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/reaction-wheel-arm.toml");
  const auto line = std::to_string(std::count(base.begin(), base.end(), '\n') + 1);
  const std::string header = "is not valid TOML: a table header must start with a key";
  // the document of the mutation corpus that tripped the assertion (mutation 1146: a slice of the
  // four-bar's `origin = { xyz = [0.2, 0.0, 0.0] }   # crank length 0.2 m` copied between the two
  // brackets of `[[mechanism.frames]]`), minimised to its first two bytes
  EXPECT_EQ(refusal("[."), "header.toml: " + header + ", saw '.' after '[' (line 1, column 2)");
  const std::string four_bar = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/four-bar.toml");
  EXPECT_EQ(refusal(four_bar + "[.2, 0.0, 0.0] }   # crank length 0.2 m\n"),
            "header.toml: " + header + ", saw '.' after '[' (line " +
                std::to_string(std::count(four_bar.begin(), four_bar.end(), '\n') + 1) + ", column 2)");
  // more of its kind, after a valid case (the text before the header is valid TOML)
  for (const auto& [tail, saw, column] : std::vector<std::tuple<std::string, std::string, int>>{
           {"[\n", "the end of the line after '['", 2},
           {"[[[1]]]\n", "'[' after '[['", 3},
           {"[=\n", "'=' after '['", 2},
           {"[[ =]]\n", "'=' after '[['", 4},
           {"  [\t# x\n", "'#' after '['", 5},
           {"[\r\n", "the end of the line after '['", 2},
           {"[\xc3\xa9]\n", "U+00E9 after '['", 2},
           {"[\xff]\n", "byte 0xff after '['", 2},
           {"[{a}]\n", "'{' after '['", 2}}) {
    EXPECT_EQ(refusal(base + tail),
              "header.toml: " + header + ", saw " + saw + " (line " + line + ", column " + std::to_string(column) + ")")
        << tail;
  }
  // an error before that line comes first, as toml++ and tomllib report it
  EXPECT_NE(refusal("a = 1 1\n[\n" + base).find("(line 1, column"), std::string::npos);
  // every byte after each opening, on the first line and after a valid case: a ConfigError naming
  // the file (the assertion, were it reached, would abort the sanitizer build)
  for (const std::string opening : {"[", "[[", "[ ", "[[ ", "\t[", "\xEF\xBB\xBF["}) {
    for (int b = 0; b < 256; ++b) {
      const std::string line = opening + static_cast<char>(b) + "\n";
      refusal(line + "x = 1\n" + base);
      refusal(base + line);
    }
  }
}

TEST(CaseFuzz, BracketsAtTheStartOfALineInsideValuesStillLoad) {
  // a `[` first on its line opens a header only outside strings, comments, arrays and inline tables
  const std::string base = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/reaction-wheel-arm.toml");
  const std::string values =
      "x = [\n[1, 2],\n  [ 3, 4 ],\n[\n\"a\",\n],\n[\n# [\n]\n]\n"
      "y = \"\"\"\n[\n[=\n\\\"\"\"\n[\n\"\"\"\n"
      "z = '''\n[=\n[[ ]]\n''''\n"
      "w = { a = [\n[1]] }\n"
      "\"q[\" = '['\n"
      "# [=\n"
      "[ \"spaced\" ]  # [=\n"
      "[[ 'arr' ]]\n"
      "[[arr]]\n";
  // read whole: the case is refused only for the tables it does not know (issue 40: as the Python
  // reader), the first in key order being the last header's [[arr]]
  for (const std::string& doc : {values + base, base + "\n[extra]\n" + values}) {
    try {
      case_from_string(doc, "values.toml");
      ADD_FAILURE() << "unknown tables accepted:\n" << doc;
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), "arr: unknown key (allowed: case, mechanism, trajectory, balance, control)")
          << e.what();
    }
  }
  // inside a table the C++ reader does not read ([balance] is mechbal balance's) they load
  EXPECT_NO_THROW(case_from_string(base + "\n[balance]\n" + values.substr(0, values.find("\n# [=")), "values.toml"));
}

TEST(CaseFuzz, BraceWhereAnArrayExpectsAValue) {
  const std::string base = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/reaction-wheel-arm.toml");
  const long lines = std::count(base.begin(), base.end(), '\n');
  const std::string what = "header.toml: is not valid TOML: expected a value or ']' in an array, saw '}'";
  // mutation 3903 of the corpus (a PAMINSA joint's `axis = [0.0, }`), minimised
  EXPECT_EQ(refusal("s=[}"), what + " (line 1, column 4)");
  EXPECT_EQ(refusal(base + "axis = [0.0, }\n"), what + " (line " + std::to_string(lines + 1) + ", column 14)");
  for (const auto& [tail, line, column] : std::vector<std::tuple<std::string, int, int>>{
           {"x = [ }\n", 1, 7}, {"x = [[1], }\n", 1, 11}, {"x = [\n  1,\n# }\n}\n", 4, 1}, {"x = { a = [} }\n", 1, 12}}) {
    EXPECT_EQ(refusal(base + tail),
              what + " (line " + std::to_string(lines + line) + ", column " + std::to_string(column) + ")")
        << tail;
  }
  // after a value the brace is toml++'s own error (no assumption broken there)
  EXPECT_NE(refusal(base + "x = [1 }\n").find("expected comma or closing ']'"), std::string::npos);
}

TEST(CaseFuzz, NonAsciiOutsideStringsAndComments) {
  const std::string base = read(MECHBAL_SOURCE_DIR "/python/mechbal/cases/reaction-wheel-arm.toml");
  const auto line = std::to_string(std::count(base.begin(), base.end(), '\n') + 1);
  const std::string what = "header.toml: is not valid TOML: the character ";
  const std::string rest = " is not ASCII: outside strings and comments TOML allows only ASCII";
  for (const auto& [tail, shown, column] : std::vector<std::tuple<std::string, std::string, int>>{
           {"\xc3\xa9 = 1\n", "U+00E9", 1},           // a key
           {"x = 1\xc3\xa9\n", "U+00E9", 6},          // after a number
           {"x = \"a\" \xe3\x80\x80\n", "U+3000", 9},  // an ideographic space
           {"x = [\xe2\x80\xa8]\n", "U+2028", 6},      // a line separator for an array's value
           {"[a]\xcc\xaa\n", "U+032A", 4},             // after a header
           {"[a.\xef\xb9\x90]\n", "U+FE50", 4},        // in a header's key
           {"x = {a = 1\xc2\xa1}\n", "U+00A1", 11},
           {"x = 1 \xff\n", "byte 0xff", 7}}) {
    EXPECT_EQ(refusal(base + tail), what + shown + rest + " (line " + line + ", column " + std::to_string(column) + ")")
        << tail;
  }
  // in strings and comments they are fine, and a string that a line-ending backslash wraps onto a
  // line that starts with one (toml++ would ask is_horizontal_whitespace about it) reads the same
  for (const auto& [name, expected] : std::vector<std::pair<std::string, std::string>>{
           {"\"arm\xc3\xa9\"  # \xc3\xa9\xe3\x80\x80", "arm\xc3\xa9"},
           {"'\xc3\xa9'", "\xc3\xa9"},
           {"\"\"\"\xc3\xa9\"\"\"", "\xc3\xa9"},
           {"'''\n\xc3\xa9'''", "\xc3\xa9"},
           {"\"\"\"arm\\\n    \xc3\xa9\\\n\n \xf0\x9f\xa4\x96 \\\r\n\t\xcc\xaa\"\"\"", "arm\xc3\xa9\xf0\x9f\xa4\x96 \xcc\xaa"},
           {"\"\"\"a\\\n\\u00e9\"\"\"", "a\xc3\xa9"}}) {
    std::string doc = base;
    const std::string from = "name = \"reaction-wheel-arm\"";
    ASSERT_NE(doc.find(from), std::string::npos);
    doc.replace(doc.find(from), from.size(), "name = " + name);
    try {
      EXPECT_EQ(case_from_string(doc, "names.toml").name, expected) << name;
    } catch (const ConfigError& e) {
      ADD_FAILURE() << name << ": " << e.what();
    }
  }
}
