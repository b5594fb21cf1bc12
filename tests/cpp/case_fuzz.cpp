// The C++ case reader (io/case.hpp) cannot be made to crash, hang or throw anything but ConfigError.
// A deterministic corpus of mutations of the built-in case files (each with a [control] table of
// every kind appended): truncations, byte flips, erased and duplicated slices, inserted TOML
// markup, values replaced by values of the wrong type or by huge numbers, deep nesting. Each
// document either loads (a model with physical bodies, its [control] checked against it, and the
// controller it describes built or refused with std::invalid_argument) or gives a one-line
// ConfigError naming a field. `make test-sanitize` runs this corpus under AddressSanitizer and
// UndefinedBehaviorSanitizer, like the URDF reader's (test_parser_fuzz.cpp); its own executable
// (mechbal_case_fuzz).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
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
  EXPECT_GE(seeds.size(), 8u);
  std::vector<int> actuated;
  const auto names = first_joint_names(seeds, actuated);
  // each seed with each kind of [control] loads
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    for (int which = 0; which < 4; ++which) {
      std::string doc = seeds[s];
      if (doc.find("\n[control]") != std::string::npos) doc = doc.substr(0, doc.find("\n[control]"));
      EXPECT_NO_THROW(case_from_string(doc + control_table(which, actuated[s], names[s]))) << s << " " << which;
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
  for (int i = 0; i < mutations; ++i) {
    const std::size_t s = static_cast<std::size_t>(i) % seeds.size();
    std::string doc = seeds[s];
    if (doc.find("\n[control]") != std::string::npos) doc = doc.substr(0, doc.find("\n[control]"));
    doc += control_table(i / static_cast<int>(seeds.size()), actuated[s], names[s]);
    check(mutate(rng, doc), out);
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
  // a little nesting is fine: the case loads (other tables are left to their own readers)
  Outcome out;
  check(nested(20, false) + base, out);
  check("a.b.c.d.e.f = 1.5\n" + base, out);
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
