// The case-format reader (io/case.hpp): toml++ -> the checked tables -> the same
// MechanismDescription as python/mechbal/spec.py. The order of the checks and the field names
// follow the Python reader (schema.py for one table at a time, spec.py for the cross references),
// so that both readers refuse the same files naming the same field.
#include "mechbal/io/case.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#define TOML_EXCEPTIONS 1
#include <toml++/toml.h>

namespace mechbal {

ConfigError::ConfigError(std::string field, const std::string& message)
    : std::invalid_argument(field.empty() ? message : field + ": " + message), field_(std::move(field)) {}

namespace {

using Mat4 = Eigen::Matrix4d;
constexpr double kMaxAbs = 1e12;           // schema.MAX_ABS
constexpr double kPlanarTol = 1e-9;        // spec.PLANAR_TOL
constexpr std::size_t kMaxJoints = 256;    // schema.MAX_JOINTS
constexpr std::size_t kMaxBodies = 1024;   // schema.MAX_BODIES
constexpr std::size_t kMaxFrames = 1024;   // schema.MAX_FRAMES
constexpr std::size_t kMaxName = 128;
const std::string kBase = "base";
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- messages ---------------------------------------------------------------------------------

/// Python's repr of a float: the shortest round trip, fixed for exponents -4..15 ("1.0",
/// "2000000.0", "0.0001"), else scientific ("1e+16", "1.5e-05").
std::string float_repr(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::scientific);
  const std::string sci(buf, r.ptr);  // [-]d[.ddd]e(+|-)XX
  const std::size_t e = sci.find('e');
  const int exponent = std::stoi(sci.substr(e + 1));
  if (exponent < -4 || exponent >= 16) return sci;
  const bool negative = sci[0] == '-';
  std::string digits;
  for (std::size_t k = negative ? 1 : 0; k < e; ++k)
    if (sci[k] != '.') digits += sci[k];
  std::string out;
  if (exponent < 0) {
    out = "0." + std::string(static_cast<std::size_t>(-exponent - 1), '0') + digits;
  } else {
    const auto point = static_cast<std::size_t>(exponent + 1);
    if (digits.size() <= point) {
      out = digits + std::string(point - digits.size(), '0') + ".0";
    } else {
      out = digits.substr(0, point) + "." + digits.substr(point);
    }
  }
  return negative ? "-" + out : out;
}

/// schema._fmt: bounds as the Python reader prints them (1e+12, 0, 1000).
std::string bound_repr(double x) {
  if (std::floor(x) == x && std::abs(x) < 1e7) return std::to_string(static_cast<long long>(x));
  std::ostringstream os;
  os << x;
  return os.str();
}

/// Python's repr of a str: single quotes (double when the text holds a single quote and no
/// double one), backslashes, the quote and control characters escaped; one line always.
std::string quote(const std::string& s) {
  const char q = s.find('\'') != std::string::npos && s.find('"') == std::string::npos ? '"' : '\'';
  std::string out(1, q);
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '\\' || ch == q) {
      out += '\\';
      out += ch;
    } else if (ch == '\n') {
      out += "\\n";
    } else if (ch == '\r') {
      out += "\\r";
    } else if (ch == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      static const char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += ch;
    }
  }
  return out + q;
}

/// A parser's message on one line: control characters escaped.
std::string one_line(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) {
      static const char hex[] = "0123456789abcdef";
      out += ch == '\n' ? std::string("\\n") : std::string("\\x") + hex[c >> 4] + hex[c & 15];
    } else {
      out += ch;
    }
  }
  return out;
}

void repr_into(const toml::node& n, std::string& out, int depth) {
  if (out.size() > 200 || depth > 8) {
    out += "...";
    return;
  }
  if (auto v = n.as_string()) {
    out += quote(v->get());
  } else if (auto i = n.as_integer()) {
    out += std::to_string(i->get());
  } else if (auto d = n.as_floating_point()) {
    out += float_repr(d->get());
  } else if (auto b = n.as_boolean()) {
    out += b->get() ? "True" : "False";
  } else if (auto a = n.as_array()) {
    out += "[";
    for (std::size_t k = 0; k < a->size(); ++k) {
      if (k) out += ", ";
      repr_into(*a->get(k), out, depth + 1);
    }
    out += "]";
  } else if (auto t = n.as_table()) {
    out += "{";
    bool first = true;
    for (auto&& [key, value] : *t) {
      if (!first) out += ", ";
      first = false;
      out += quote(std::string(key.str())) + ": ";
      repr_into(value, out, depth + 1);
    }
    out += "}";
  } else {
    std::ostringstream os;  // dates and times: the Python reader shows them as datetime objects
    os << "<" << n.type() << ">";
    out += os.str();
  }
}

/// errors.short_repr: the value as the Python reader shows it, cut at 80 characters.
std::string repr(const toml::node& n) {
  std::string s;
  repr_into(n, s, 0);
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

[[noreturn]] void fail(const std::string& field, const std::string& message) { throw ConfigError(field, message); }
[[noreturn]] void fail(const std::string& field, const std::string& message, const std::string& value_repr) {
  throw ConfigError(field, message + " (got " + value_repr + ")");
}
[[noreturn]] void fail(const std::string& field, const std::string& message, const toml::node& value) {
  fail(field, message, repr(value));
}

/// difflib.SequenceMatcher's matching characters (longest common block, then both sides).
std::size_t matching(const std::string& a, const std::string& b) {
  std::size_t best = 0, ia = 0, ib = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      std::size_t k = 0;
      while (i + k < a.size() && j + k < b.size() && a[i + k] == b[j + k]) ++k;
      if (k > best) best = k, ia = i, ib = j;
    }
  }
  if (best == 0) return 0;
  return best + matching(a.substr(0, ia), b.substr(0, ib)) + matching(a.substr(ia + best), b.substr(ib + best));
}

double similarity(const std::string& a, const std::string& b) {
  if (a.size() > 256 || b.size() > 256) return 0.0;
  const double total = static_cast<double>(a.size() + b.size());
  return total == 0.0 ? 1.0 : 2.0 * static_cast<double>(matching(a, b)) / total;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// difflib.get_close_matches(word, candidates, n=1, cutoff=0.6): the best ratio, ties to the
/// largest word (heapq.nlargest over (ratio, word)); nullptr when none reaches the cutoff.
const std::string* closest(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string* best = nullptr;
  double best_ratio = 0.0;
  for (const auto& a : candidates) {
    const double r = similarity(word, a);
    if (r < 0.6) continue;
    if (best == nullptr || r > best_ratio || (r == best_ratio && a > *best)) best = &a, best_ratio = r;
  }
  return best;
}

/// schema.did_you_mean: " (did you mean 'x'?)" for the nearest allowed word (as written, then
/// ignoring case), else the list.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& allowed) {
  const std::string* match = closest(word, allowed);
  if (!match) {
    // {a.lower(): a}: the last word of each lowercase spelling, in order of first appearance
    std::vector<std::string> lowers;
    std::map<std::string, const std::string*> by_lower;
    for (const auto& a : allowed) {
      const std::string l = lower(a);
      if (!by_lower.count(l)) lowers.push_back(l);
      by_lower[l] = &a;
    }
    const std::string lw = lower(word);
    if (by_lower.count(lw)) {
      match = by_lower[lw];
    } else if (const std::string* m = closest(lw, lowers)) {
      match = by_lower[*m];
    }
  }
  if (match) return " (did you mean " + quote(*match) + "?)";
  if (allowed.empty()) return "";
  std::string out = " (allowed: ";
  for (std::size_t k = 0; k < allowed.size(); ++k) out += (k ? ", " : "") + allowed[k];
  return out + ")";
}

std::string join(const std::string& prefix, const std::string& key) { return prefix.empty() ? key : prefix + "." + key; }
std::string item(const std::string& prefix, std::size_t i) { return prefix + "[" + std::to_string(i) + "]"; }

// ---- values -----------------------------------------------------------------------------------

const toml::table& table_of(const toml::node& n, const std::string& f) {
  if (!n.is_table()) fail(f, "must be a table", n);
  return *n.as_table();
}

/// Unknown keys are errors naming the nearest allowed key (the Python reader's extra_forbidden).
void allow_keys(const toml::table& t, const std::string& f, const std::vector<std::string>& allowed) {
  for (auto&& [k, v] : t) {
    const std::string key(k.str());
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::vector<std::string> absent;
    for (const auto& a : allowed)
      if (!t.contains(a)) absent.push_back(a);
    std::string hint = did_you_mean(key, absent);
    if (hint.find("did you") == std::string::npos) hint = did_you_mean(key, allowed);
    fail(join(f, key), std::string(v.is_table() ? "unknown table" : "unknown key") + hint);
  }
}

const toml::node* get(const toml::table& t, const char* key) { return t.get(key); }

const toml::node& required(const toml::table& t, const char* key, const std::string& f) {
  const toml::node* n = t.get(key);
  if (!n) fail(join(f, key), "is required");
  return *n;
}

enum class Lo { ge, gt };

/// A finite number (TOML integer or float, not a boolean) within [lo, hi] (or (lo, hi]).
double number(const toml::node& n, const std::string& f, double lo = -kMaxAbs, double hi = kMaxAbs,
              Lo lo_kind = Lo::ge) {
  double x;
  if (auto i = n.as_integer()) {
    x = static_cast<double>(i->get());
  } else if (auto d = n.as_floating_point()) {
    x = d->get();
  } else {
    fail(f, "must be a number", n);
  }
  if (!std::isfinite(x)) fail(f, "must be finite", n);
  if (lo_kind == Lo::gt ? !(x > lo) : !(x >= lo)) fail(f, std::string("must be ") + (lo_kind == Lo::gt ? ">" : ">=") + " " + bound_repr(lo), n);
  if (!(x <= hi)) fail(f, "must be <= " + bound_repr(hi), n);
  return x;
}

long long integer(const toml::node& n, const std::string& f, long long lo, long long hi) {
  auto i = n.as_integer();
  if (!i) fail(f, "must be an integer", n);
  const long long x = i->get();
  if (x < lo) fail(f, "must be >= " + std::to_string(lo), n);
  if (x > hi) fail(f, "must be <= " + std::to_string(hi), n);
  return x;
}

std::size_t utf8_length(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

/// A name: a string of 1..128 characters.
std::string name(const toml::node& n, const std::string& f) {
  auto s = n.as_string();
  if (!s) fail(f, "must be a string", n);
  const std::string v = s->get();
  if (v.empty()) fail(f, "must not be empty", n);
  if (utf8_length(v) > kMaxName) fail(f, "must have at most 128 characters", n);
  // the character set of names (model.hpp name_problem; tables.Name): printable, XML-safe
  if (const std::string why = name_problem(v); !why.empty()) fail(f, why, n);
  return v;
}

std::string choice(const toml::node& n, const std::string& f, const std::vector<std::string>& choices) {
  auto s = n.as_string();
  std::string text = "must be one of ";
  for (std::size_t k = 0; k < choices.size(); ++k) text += (k ? ", " : "") + choices[k];
  if (!s) fail(f, text, n);
  const std::string v = s->get();
  if (std::find(choices.begin(), choices.end(), v) != choices.end()) return v;
  std::string hint = did_you_mean(v, choices);
  if (hint.rfind(" (allowed", 0) == 0) hint.clear();
  fail(f, text + hint, n);
}

const toml::array& array_of(const toml::node& n, const std::string& f, std::size_t min_len, std::size_t max_len) {
  auto a = n.as_array();
  if (!a) fail(f, "must be a list", n);
  if (min_len == max_len && a->size() != min_len) fail(f, "must have " + std::to_string(min_len) + " values", n);
  if (a->size() < min_len) fail(f, "must have at least " + std::to_string(min_len) + " values", n);
  if (a->size() > max_len) fail(f, "must have at most " + std::to_string(max_len) + " values", n);
  return *a;
}

Vec3 vec3(const toml::node& n, const std::string& f, double lo = -kMaxAbs, double hi = kMaxAbs, Lo lo_kind = Lo::ge) {
  const toml::array& a = array_of(n, f, 3, 3);
  Vec3 v;
  for (std::size_t k = 0; k < 3; ++k) v[static_cast<int>(k)] = number(*a.get(k), item(f, k), lo, hi, lo_kind);
  return v;
}

Vec3 vec3_or(const toml::table& t, const char* key, const std::string& f, const Vec3& fallback) {
  const toml::node* n = get(t, key);
  return n ? vec3(*n, join(f, key)) : fallback;
}

std::string fmt6(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

/// The physical checks of an inertia (symmetric, positive semi-definite, triangle inequality).
Mat3 checked_inertia(const Mat3& I, const std::string& f, const toml::node& n) {
  const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) fail(f, "must be symmetric", n);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I, Eigen::EigenvaluesOnly);
  const Vec3 p = eig.eigenvalues();
  const double tol = 1e-12 * scale;
  if (p[0] < -tol) fail(f, "must be positive semi-definite, smallest principal moment is " + fmt6(p[0]), n);
  if (p[2] > p[0] + p[1] + tol) {
    fail(f, "violates the triangle inequality of a physical body: principal moments " + fmt6(p[0]) + ", " +
                fmt6(p[1]) + ", " + fmt6(p[2]), n);
  }
  return I;
}

/// schema.inertia_matrix: a table {ixx, iyy, izz, ixy, ixz, iyz} (the moments required, absent
/// products 0, no other key), 3x3, [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]; symmetric,
/// positive semi-definite, triangle inequality.
Mat3 inertia_matrix(const toml::node& n, const std::string& f) {
  const char* shape = "must be a table {ixx, iyy, izz, ixy, ixz, iyz}, a 3x3 matrix, [Ixx, Iyy, Izz] or "
                      "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]";
  static const char* const kNamed[6] = {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"};
  if (auto t = n.as_table()) {
    allow_keys(*t, f, {kNamed, kNamed + 6});
    for (int k = 0; k < 3; ++k) required(*t, kNamed[k], f);
    double v[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 6; ++k)
      if (const toml::node* x = get(*t, kNamed[k])) v[k] = number(*x, join(f, kNamed[k]));
    Mat3 I;
    I << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
    return checked_inertia(I, f, n);
  }
  auto a = n.as_array();
  if (!a) fail(f, shape, n);
  std::size_t rows = 0;
  for (auto&& x : *a) rows += x.is_array();
  if (rows && (a->size() != 3 || rows != 3)) fail(f, shape, n);
  if (rows) {
    for (auto&& r : *a)
      if (r.as_array()->size() != 3) fail(f, shape, n);
  } else if (a->size() != 3 && a->size() != 6) {
    fail(f, shape, n);
  }
  std::vector<std::pair<std::string, const toml::node*>> entries;
  if (rows) {
    for (std::size_t i = 0; i < 3; ++i)
      for (std::size_t k = 0; k < 3; ++k)
        entries.emplace_back("[" + std::to_string(i) + "][" + std::to_string(k) + "]", a->get(i)->as_array()->get(k));
  } else {
    for (std::size_t i = 0; i < a->size(); ++i) entries.emplace_back("[" + std::to_string(i) + "]", a->get(i));
  }
  std::vector<double> v;
  for (auto& [sub, x] : entries) {
    double d;
    if (auto i = x->as_integer()) {
      d = static_cast<double>(i->get());
    } else if (auto fp = x->as_floating_point()) {
      d = fp->get();
    } else {
      fail(f + sub, "must be a number", *x);
    }
    if (!std::isfinite(d)) fail(f + sub, "must be finite", *x);
    if (std::abs(d) > kMaxAbs) fail(f + sub, "must be between -1e+12 and 1e+12", *x);
    v.push_back(d);
  }
  Mat3 I = Mat3::Zero();
  if (rows) {
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) I(i, k) = v[static_cast<std::size_t>(3 * i + k)];
  } else {
    I.diagonal() << v[0], v[1], v[2];
    if (v.size() == 6) {
      I(0, 1) = I(1, 0) = v[3];
      I(0, 2) = I(2, 0) = v[4];
      I(1, 2) = I(2, 1) = v[5];
    }
  }
  return checked_inertia(I, f, n);
}

// ---- transforms (spec.py) ---------------------------------------------------------------------

Mat3 rotation_rpy(const Vec3& rpy) {
  const double cr = std::cos(rpy[0]), sr = std::sin(rpy[0]), cp = std::cos(rpy[1]), sp = std::sin(rpy[1]),
               cy = std::cos(rpy[2]), sy = std::sin(rpy[2]);
  Mat3 Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  Ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  Rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
  return Rz * Ry * Rx;
}

Mat4 transform(const Vec3& xyz, const Vec3& rpy) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = rotation_rpy(rpy);
  T.topRightCorner<3, 1>() = xyz;
  return T;
}

Mat4 rx(double t) { return transform(Vec3::Zero(), Vec3(t, 0.0, 0.0)); }
Mat4 rz(double t) { return transform(Vec3::Zero(), Vec3(0.0, 0.0, t)); }
Mat4 tr(double x, double y, double z) { return transform(Vec3(x, y, z), Vec3::Zero()); }

// ---- the [mechanism] table as read (schema.py's models) ---------------------------------------

struct OriginIn {
  Vec3 xyz = Vec3::Zero(), rpy = Vec3::Zero();
};
struct DHIn {
  double a = 0, alpha = 0, d = 0, theta = 0;
};
struct MimicIn {
  std::string joint;
  double ratio = 1.0, offset = 0.0;
};
struct LinkIn {
  double mass = 0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
  std::optional<double> izz;  ///< given alone: a planar mechanism's lamina (lamina_inertia)
};
struct JointIn {
  std::optional<std::string> name, parent;
  std::string type = "revolute";
  std::optional<OriginIn> origin;
  std::optional<DHIn> mdh, dh;
  std::optional<Vec3> axis;
  std::optional<double> lower, upper, velocity, effort;
  std::optional<MimicIn> mimic;
  std::optional<LinkIn> link;
};
struct BodyIn {
  std::string name, kind = "other", link;
  double mass = 0;
  Vec3 com = Vec3::Zero(), rpy = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
  std::optional<double> izz;
};

/// tables.lamina_inertia: izz given alone is a thin lamina in the plane normal to `n` (the body's
/// axes): izz about n, izz / 2 about every in-plane axis, izz / 2 (1 + n n^T).
Mat3 lamina_inertia(double izz, const Vec3& normal) {
  const Vec3 n = normal / normal.norm();
  return 0.5 * izz * (Mat3::Identity() + n * n.transpose());
}

/// tables._one_inertia: `inertia`, or `izz` alone (checked after every key, as the Python model
/// validator is; `rpy` orients inertia axes, which izz alone has not).
void one_inertia(const toml::table& t, const std::string& f) {
  const toml::node* in = get(t, "inertia");
  const toml::node* z = get(t, "izz");
  if (!in && !z) fail(join(f, "inertia"), "is required (or izz alone, for a planar mechanism)");
  if (in && z) fail(join(f, "izz"), "give inertia or izz, not both", *z);
  if (z && get(t, "rpy")) fail(join(f, "rpy"), "orients the inertia axes; izz alone is about the plane's normal: drop rpy", *get(t, "rpy"));
}

struct FrameIn {
  std::string name, link;
  OriginIn origin;
};
struct LoopIn {
  std::string name, type = "point", frame_a, frame_b;
};
struct SpringIn {
  std::string name, link_a, link_b;
  Vec3 anchor_a = Vec3::Zero(), anchor_b = Vec3::Zero();
  double rate = 0, free_length = 0, preload = 0, pulley_ratio = 1.0;
  int count = 1;
};
struct MechanismIn {
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
  std::optional<OriginIn> base;
  std::vector<JointIn> joints;
  std::vector<BodyIn> bodies;
  std::vector<FrameIn> frames;
  std::vector<LoopIn> loops;
  std::vector<std::string> actuated;
  std::vector<SpringIn> springs;
};

OriginIn read_origin(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"xyz", "rpy"});
  OriginIn o;
  o.xyz = vec3_or(t, "xyz", f, Vec3::Zero());
  o.rpy = vec3_or(t, "rpy", f, Vec3::Zero());
  return o;
}

DHIn read_dh(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"a", "alpha", "d", "theta"});
  DHIn d;
  d.a = number(required(t, "a", f), join(f, "a"));
  d.alpha = number(required(t, "alpha", f), join(f, "alpha"));
  if (auto x = get(t, "d")) d.d = number(*x, join(f, "d"));
  if (auto x = get(t, "theta")) d.theta = number(*x, join(f, "theta"));
  return d;
}

JointIn read_joint(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"name", "type", "parent", "origin", "mdh", "dh", "axis", "limits", "mimic", "link"});
  JointIn j;
  if (auto x = get(t, "name")) j.name = name(*x, join(f, "name"));
  if (auto x = get(t, "type")) j.type = choice(*x, join(f, "type"), {"revolute", "prismatic", "fixed", "spherical"});
  if (auto x = get(t, "parent")) j.parent = name(*x, join(f, "parent"));
  if (auto x = get(t, "origin")) j.origin = read_origin(*x, join(f, "origin"));
  if (auto x = get(t, "mdh")) j.mdh = read_dh(*x, join(f, "mdh"));
  if (auto x = get(t, "dh")) j.dh = read_dh(*x, join(f, "dh"));
  if (auto x = get(t, "axis")) j.axis = vec3(*x, join(f, "axis"));
  if (auto x = get(t, "limits")) {
    const std::string fl = join(f, "limits");
    const auto& l = table_of(*x, fl);
    allow_keys(l, fl, {"lower", "upper", "velocity", "effort"});
    if (auto y = get(l, "lower")) j.lower = number(*y, join(fl, "lower"));
    if (auto y = get(l, "upper")) j.upper = number(*y, join(fl, "upper"));
    if (auto y = get(l, "velocity")) j.velocity = number(*y, join(fl, "velocity"), 0.0, kMaxAbs, Lo::gt);
    if (auto y = get(l, "effort")) j.effort = number(*y, join(fl, "effort"), 0.0, kMaxAbs, Lo::gt);
    if (j.lower && j.upper && *j.lower > *j.upper) {
      fail(join(fl, "upper"), "must be >= lower = " + float_repr(*j.lower), *get(l, "upper"));
    }
  }
  if (auto x = get(t, "mimic")) {
    const std::string fm = join(f, "mimic");
    const auto& m = table_of(*x, fm);
    allow_keys(m, fm, {"joint", "ratio", "offset"});
    MimicIn mi;
    mi.joint = name(required(m, "joint", fm), join(fm, "joint"));
    if (auto y = get(m, "ratio")) mi.ratio = number(*y, join(fm, "ratio"));
    if (auto y = get(m, "offset")) mi.offset = number(*y, join(fm, "offset"));
    j.mimic = mi;
  }
  if (auto x = get(t, "link")) {
    const std::string fk = join(f, "link");
    const auto& l = table_of(*x, fk);
    allow_keys(l, fk, {"mass", "com", "inertia", "izz"});
    LinkIn li;
    li.mass = number(required(l, "mass", fk), join(fk, "mass"), 0.0);
    li.com = vec3_or(l, "com", fk, Vec3::Zero());
    if (auto y = get(l, "inertia")) li.inertia = inertia_matrix(*y, join(fk, "inertia"));
    if (auto y = get(l, "izz")) li.izz = number(*y, join(fk, "izz"), 0.0);
    one_inertia(l, fk);
    j.link = li;
  }
  // Joint._consistent
  std::vector<std::string> given;
  if (j.origin) given.push_back("origin");
  if (j.mdh) given.push_back("mdh");
  if (j.dh) given.push_back("dh");
  if (given.size() > 1) {
    std::string v = "[";
    for (std::size_t k = 0; k < given.size(); ++k) v += (k ? ", " : "") + quote(given[k]);
    fail(f, "give only one of origin, mdh, dh", v + "]");
  }
  if (j.axis) {
    if (!given.empty() && given[0] != "origin") fail(join(f, "axis"), "DH joints move along/about z; drop axis", *get(t, "axis"));
    if (j.type == "fixed" || j.type == "spherical") {
      fail(join(f, "axis"), "a " + j.type + " joint has no axis; drop it", *get(t, "axis"));
    }
    const double scale = j.axis->cwiseAbs().maxCoeff();
    if (scale == 0.0 || (*j.axis / scale).norm() * scale < 1e-12) {
      fail(join(f, "axis"), "must be a non-zero vector", *get(t, "axis"));
    }
  }
  for (const char* key : {"limits", "mimic"}) {
    if (get(t, key) && (j.type == "fixed" || j.type == "spherical")) {
      fail(join(f, key), "a " + j.type + " joint cannot have " + key, *get(t, key));
    }
  }
  return j;
}

BodyIn read_body(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"name", "kind", "link", "mass", "com", "inertia", "izz", "rpy"});
  BodyIn b;
  b.name = name(required(t, "name", f), join(f, "name"));
  if (auto x = get(t, "kind")) {
    b.kind = choice(*x, join(f, "kind"), {"link", "counterweight", "motor", "disc", "payload", "other"});
  }
  b.link = name(required(t, "link", f), join(f, "link"));
  b.mass = number(required(t, "mass", f), join(f, "mass"), 0.0);
  b.com = vec3_or(t, "com", f, Vec3::Zero());
  if (auto x = get(t, "inertia")) b.inertia = inertia_matrix(*x, join(f, "inertia"));
  if (auto x = get(t, "izz")) b.izz = number(*x, join(f, "izz"), 0.0);
  b.rpy = vec3_or(t, "rpy", f, Vec3::Zero());
  one_inertia(t, f);
  return b;
}

FrameIn read_frame(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"name", "link", "origin"});
  FrameIn fr;
  fr.name = name(required(t, "name", f), join(f, "name"));
  fr.link = name(required(t, "link", f), join(f, "link"));
  if (auto x = get(t, "origin")) fr.origin = read_origin(*x, join(f, "origin"));
  return fr;
}

LoopIn read_loop(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"name", "type", "frame_a", "frame_b"});
  LoopIn l;
  l.name = name(required(t, "name", f), join(f, "name"));
  if (auto x = get(t, "type")) l.type = choice(*x, join(f, "type"), {"point", "planar_point", "axis", "weld"});
  l.frame_a = name(required(t, "frame_a", f), join(f, "frame_a"));
  l.frame_b = name(required(t, "frame_b", f), join(f, "frame_b"));
  return l;
}

SpringIn read_spring(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"name", "link_a", "anchor_a", "link_b", "anchor_b", "rate", "free_length", "preload", "count",
                    "pulley_ratio"});
  SpringIn s;
  s.name = name(required(t, "name", f), join(f, "name"));
  s.link_a = name(required(t, "link_a", f), join(f, "link_a"));
  s.anchor_a = vec3(required(t, "anchor_a", f), join(f, "anchor_a"));
  s.link_b = name(required(t, "link_b", f), join(f, "link_b"));
  s.anchor_b = vec3(required(t, "anchor_b", f), join(f, "anchor_b"));
  s.rate = number(required(t, "rate", f), join(f, "rate"), 0.0);
  if (auto x = get(t, "free_length")) s.free_length = number(*x, join(f, "free_length"), 0.0);
  if (auto x = get(t, "preload")) s.preload = number(*x, join(f, "preload"), 0.0);
  if (auto x = get(t, "count")) s.count = static_cast<int>(integer(*x, join(f, "count"), 1, 1000));
  if (auto x = get(t, "pulley_ratio")) s.pulley_ratio = number(*x, join(f, "pulley_ratio"), 0.0, 1000.0, Lo::gt);
  return s;
}

template <typename T, typename Read>
std::vector<T> read_list(const toml::table& t, const char* key, const std::string& f, std::size_t min_len,
                         std::size_t max_len, Read read) {
  std::vector<T> out;
  const toml::node* n = get(t, key);
  if (!n) {
    if (min_len > 0) fail(join(f, key), "is required");
    return out;
  }
  const std::string fl = join(f, key);
  const toml::array& a = array_of(*n, fl, min_len, max_len);
  for (std::size_t k = 0; k < a.size(); ++k) out.push_back(read(*a.get(k), item(fl, k)));
  return out;
}

MechanismIn read_mechanism(const toml::node& n, const std::string& f) {
  const auto& t = table_of(n, f);
  allow_keys(t, f, {"gravity", "base", "joints", "bodies", "frames", "loops", "actuated", "springs"});
  MechanismIn m;
  m.gravity = vec3_or(t, "gravity", f, m.gravity);
  if (auto x = get(t, "base")) m.base = read_origin(*x, join(f, "base"));
  m.joints = read_list<JointIn>(t, "joints", f, 1, kMaxJoints, read_joint);
  m.bodies = read_list<BodyIn>(t, "bodies", f, 0, kMaxBodies, read_body);
  m.frames = read_list<FrameIn>(t, "frames", f, 0, kMaxFrames, read_frame);
  m.loops = read_list<LoopIn>(t, "loops", f, 0, kMaxFrames, read_loop);
  m.actuated = read_list<std::string>(t, "actuated", f, 0, kMaxJoints, name);
  m.springs = read_list<SpringIn>(t, "springs", f, 0, kMaxBodies, read_spring);
  return m;
}

// ---- cross references and placements (spec.mechanism_spec) -------------------------------------

std::string list_repr(const std::vector<std::string>& names) {
  std::string v = "[";
  for (std::size_t k = 0; k < names.size(); ++k) v += (k ? ", " : "") + quote(names[k]);
  return v + "]";
}

std::pair<Vec3, Mat3> move_body(const Mat4& T, const Vec3& com, const Mat3& inertia) {
  const Mat3 R = T.topLeftCorner<3, 3>();
  return {R * com + T.topRightCorner<3, 1>(), R * inertia * R.transpose()};
}

MechanismDescription build_description(const MechanismIn& m, const std::string& field) {
  const Mat4 base = m.base ? transform(m.base->xyz, m.base->rpy) : Mat4::Identity();
  const std::size_t nj = m.joints.size();
  auto jf = [&](std::size_t i) { return item(join(field, "joints"), i); };

  // names, spherical expansions, what each name a user may refer to means
  std::vector<std::string> names(nj);
  for (std::size_t i = 0; i < nj; ++i) names[i] = m.joints[i].name ? *m.joints[i].name : "joint" + std::to_string(i + 1);
  std::map<std::string, std::string> declared;    // spec joint name -> field declaring it
  std::map<std::string, std::string> link_joint;  // a name a user may refer to -> spec joint of its link
  std::vector<std::string> reference_order;       // link_joint's keys in insertion order
  std::vector<std::vector<std::string>> expansions(nj);
  for (std::size_t i = 0; i < nj; ++i) {
    const std::string& nm = names[i];
    const std::string f = join(jf(i), "name");
    if (nm == kBase) fail(f, "'base' is the name of the fixed base; choose another", quote(nm));
    std::vector<std::string> parts =
        m.joints[i].type == "spherical" ? std::vector<std::string>{nm + "_z", nm + "_y", nm + "_x"} : std::vector<std::string>{nm};
    std::vector<std::string> check = parts;
    if (std::find(check.begin(), check.end(), nm) == check.end()) check.push_back(nm);
    for (const auto& n : check) {
      if (declared.count(n) || link_joint.count(n)) {
        const std::string other = declared.count(n) ? declared[n] : declared[link_joint[n]];
        const std::string what =
            "the joint " + quote(n) + (n != nm ? " of the spherical joint " + quote(nm) : std::string());
        fail(f, "duplicate name: " + what + " is also declared by " + other, quote(nm));
      }
    }
    for (const auto& n : parts) {
      declared[n] = n == nm ? jf(i) : jf(i) + " (spherical " + quote(nm) + ")";
      link_joint[n] = n;
      reference_order.push_back(n);
    }
    if (!link_joint.count(nm)) reference_order.push_back(nm);
    link_joint[nm] = parts.back();
    expansions[i] = parts;
  }
  std::vector<std::string> references = reference_order;
  references.push_back(kBase);

  auto resolve = [&](const std::string& ref, const std::string& f, const std::string& what) -> std::string {
    if (ref == kBase) return kBase;
    auto it = link_joint.find(ref);
    if (it == link_joint.end()) fail(f, "unknown " + what + did_you_mean(ref, references), quote(ref));
    return it->second;
  };

  // parents (default: the previous joint), cycles
  std::map<std::string, std::size_t> index_of;
  for (std::size_t i = 0; i < nj; ++i) {
    for (const auto& n : expansions[i]) index_of[n] = i;
    index_of[names[i]] = i;
  }
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  std::vector<std::size_t> parent_index(nj, none);
  std::vector<std::string> parent_name(nj);
  for (std::size_t i = 0; i < nj; ++i) {
    const auto& j = m.joints[i];
    const std::string ref = j.parent ? *j.parent : (i > 0 ? names[i - 1] : kBase);
    const std::string parent = resolve(ref, join(jf(i), "parent"), "parent joint");
    parent_name[i] = parent;
    const std::size_t k = parent == kBase ? none : index_of[parent];
    if (k == i && std::find(expansions[i].begin(), expansions[i].end(), parent) != expansions[i].end()) {
      fail(join(jf(i), "parent"), "a joint cannot be its own parent", quote(ref));
    }
    parent_index[i] = k;
  }
  for (std::size_t i = 0; i < nj; ++i) {
    std::vector<std::size_t> path{i};
    std::size_t k = parent_index[i];
    while (k != none) {
      auto at = std::find(path.begin(), path.end(), k);
      if (at != path.end()) {
        std::vector<std::size_t> cycle(at, path.end());
        cycle.push_back(k);
        const std::size_t start = *std::min_element(cycle.begin(), cycle.end());
        std::string text = "joints form a cycle: ";
        for (std::size_t c = 0; c < cycle.size(); ++c) text += (c ? " -> " : "") + names[cycle[c]];
        fail(join(jf(start), "parent"), text, quote(parent_name[start]));
      }
      path.push_back(k);
      k = parent_index[k];
    }
  }

  // parents first, the file's order where it already is
  std::vector<std::size_t> order;
  std::vector<bool> placed(nj, false);
  while (order.size() < nj) {
    for (std::size_t i = 0; i < nj; ++i) {
      if (!placed[i] && (parent_index[i] == none || placed[parent_index[i]])) {
        order.push_back(i);
        placed[i] = true;
      }
    }
  }

  // placements and carries
  std::vector<Mat4> origin_of(nj), carry_of(nj);
  for (std::size_t i = 0; i < nj; ++i) {
    const auto& j = m.joints[i];
    if (j.mdh || j.dh) {
      const DHIn& d = j.mdh ? *j.mdh : *j.dh;
      if (j.mdh) {
        origin_of[i] = rx(d.alpha) * tr(d.a, 0, 0) * tr(0, 0, d.d) * rz(d.theta);
        carry_of[i] = Mat4::Identity();
      } else {
        origin_of[i] = rz(d.theta);
        carry_of[i] = tr(0, 0, d.d) * tr(d.a, 0, 0) * rx(d.alpha);
      }
    } else {
      origin_of[i] = j.origin ? transform(j.origin->xyz, j.origin->rpy) : Mat4::Identity();
      carry_of[i] = Mat4::Identity();
    }
  }
  std::map<std::string, Mat4> carry_by_joint;
  for (std::size_t i = 0; i < nj; ++i)
    for (const auto& n : expansions[i]) carry_by_joint[n] = n == expansions[i].back() ? carry_of[i] : Mat4::Identity();
  auto frame_of_link = [&](const std::string& link) -> Mat4 { return link == kBase ? base : carry_by_joint.at(link); };
  auto iso = [](const Mat4& T) {
    Eigen::Isometry3d X;
    X.matrix() = T;
    return X;
  };

  MechanismDescription desc;
  desc.root_name = kBase;
  desc.gravity = m.gravity;
  for (std::size_t i : order) {
    const auto& j = m.joints[i];
    const std::string& parent = parent_name[i];
    const Mat4 placement = frame_of_link(parent) * origin_of[i];
    if (j.type == "spherical") {
      const auto& parts = expansions[i];
      const std::string parents[3] = {parent, parts[0], parts[1]};
      const Vec3 axes[3] = {Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitX()};
      for (int k = 0; k < 3; ++k) {
        Joint out;
        out.name = parts[static_cast<std::size_t>(k)];
        out.type = JointType::revolute;
        out.parent = parents[k];
        out.placement = iso(k == 0 ? placement : Mat4::Identity());
        out.axis = axes[k];
        desc.joints.push_back(out);
      }
      continue;
    }
    Joint out;
    out.name = names[i];
    out.type = j.type == "revolute" ? JointType::revolute : j.type == "prismatic" ? JointType::prismatic : JointType::fixed;
    out.parent = parent;
    out.placement = iso(placement);
    Vec3 axis = j.axis ? *j.axis : Vec3::UnitZ();
    axis = axis / axis.cwiseAbs().maxCoeff();
    out.axis = axis / axis.norm();
    out.lower = j.lower ? *j.lower : -kInf;
    out.upper = j.upper ? *j.upper : kInf;
    out.velocity_limit = j.velocity ? *j.velocity : kInf;
    out.effort_limit = j.effort ? *j.effort : kInf;
    if (j.mimic) {
      const std::string f = join(join(jf(i), "mimic"), "joint");
      const std::string& ref = j.mimic->joint;
      auto k = index_of.find(ref);
      if (k != index_of.end() && m.joints[k->second].type == "spherical" && ref == names[k->second]) {
        const auto& e = expansions[k->second];
        fail(f, quote(ref) + " is a spherical joint: name one of " + e[0] + ", " + e[1] + ", " + e[2], quote(ref));
      }
      const std::string master = resolve(ref, f, "joint");
      if (master == kBase) fail(f, "the base does not move: name a joint", quote(ref));
      if (master == names[i]) fail(f, "a joint cannot mimic itself", quote(ref));
      const JointIn& mj = m.joints[index_of[master]];
      if (mj.type == "fixed") fail(f, "mimics a fixed joint, which does not move", quote(ref));
      if (mj.mimic) {
        fail(f, "mimics " + quote(master) + ", itself a mimic of " + quote(mj.mimic->joint) + ": couple to " +
                    quote(mj.mimic->joint) + " directly", quote(ref));
      }
      out.mimic_joint = master;
      out.mimic_ratio = j.mimic->ratio;
      out.mimic_offset = j.mimic->offset;
    }
    desc.joints.push_back(out);
  }

  // bodies: each joint's own link, then the extra bodies
  std::map<std::string, std::string> body_field;
  auto add_body = [&](const std::string& nm, const std::string& kind, const std::string& link, double mass,
                      const Vec3& com, const Mat3& inertia, const std::string& f) {
    auto it = body_field.find(nm);
    if (it != body_field.end()) fail(f, "duplicate body name: " + quote(nm) + " is also " + it->second, quote(nm));
    body_field[nm] = f;
    auto [c, I] = move_body(frame_of_link(link), com, inertia);
    Body b;
    b.name = nm;
    b.kind = kind;
    b.link = link;
    b.mass = mass;
    b.com = c;
    b.inertia = 0.5 * (I + I.transpose());
    desc.bodies.push_back(b);
  };
  // izz alone (spec.plane_normal): a lamina in the plane of motion, whose normal is the joints'
  // common axis in O at q = 0
  std::map<std::string, Mat3> rotation_in_o{{kBase, Mat3::Identity()}};
  for (const Joint& js : desc.joints) rotation_in_o[js.name] = rotation_in_o.at(js.parent) * js.placement.linear();
  auto plane_normal = [&](const std::string& f, double izz) -> Vec3 {
    const Joint* first = nullptr;
    for (const Joint& js : desc.joints) {
      if (js.type == JointType::revolute) {
        first = &js;
        break;
      }
    }
    if (!first) {
      fail(f, "izz alone needs a planar mechanism with a revolute joint (its axis is the plane's normal); give "
              "inertia = [Ixx, Iyy, Izz]", float_repr(izz));
    }
    const Vec3 a0 = rotation_in_o.at(first->name) * first->axis;
    const Vec3 n = a0 / a0.norm();
    for (const Joint& js : desc.joints) {
      if (js.type != JointType::revolute && js.type != JointType::prismatic) continue;
      const Vec3 r = rotation_in_o.at(js.name) * js.axis;
      const Vec3 a = r / r.norm();
      const bool revolute = js.type == JointType::revolute;
      const double off = revolute ? a.cross(n).norm() : std::abs(a.dot(n));
      if (off > kPlanarTol) {
        fail(f, "izz alone needs a planar mechanism (every revolute axis parallel, every prismatic axis "
                "perpendicular to the first revolute axis in O): joint " + quote(js.name) + " (" +
                    (revolute ? "revolute" : "prismatic") + ") is not; give inertia = [Ixx, Iyy, Izz]",
             float_repr(izz));
      }
    }
    return n;
  };
  auto lamina = [&](const std::string& link, double izz, const std::string& f) -> Mat3 {
    const Vec3 n = plane_normal(f, izz);
    const Mat3 R = rotation_in_o.at(link) * frame_of_link(link).topLeftCorner<3, 3>();
    return lamina_inertia(izz, R.transpose() * n);
  };
  for (std::size_t i : order) {
    const auto& j = m.joints[i];
    if (j.link) {
      const std::string& link = expansions[i].back();
      const Mat3 inertia = j.link->izz ? lamina(link, *j.link->izz, join(join(jf(i), "link"), "izz")) : j.link->inertia;
      add_body(names[i], "link", link, j.link->mass, j.link->com, inertia, join(jf(i), "link"));
    }
  }
  for (std::size_t k = 0; k < m.bodies.size(); ++k) {
    const auto& b = m.bodies[k];
    const std::string f = item(join(field, "bodies"), k);
    const std::string link = resolve(b.link, join(f, "link"), "link");
    const Mat3 R = rotation_rpy(b.rpy);
    const Mat3 inertia = b.izz ? lamina(link, *b.izz, join(f, "izz")) : Mat3(R * b.inertia * R.transpose());
    add_body(b.name, b.kind, link, b.mass, b.com, inertia, join(f, "name"));
  }

  std::map<std::string, std::string> frame_field;
  std::vector<std::string> frame_names;
  for (std::size_t k = 0; k < m.frames.size(); ++k) {
    const auto& fr = m.frames[k];
    const std::string f = item(join(field, "frames"), k);
    auto it = frame_field.find(fr.name);
    if (it != frame_field.end()) fail(join(f, "name"), "duplicate frame name: also " + it->second, quote(fr.name));
    if (fr.name == kBase) fail(join(f, "name"), "'base' is the name of the fixed base; choose another", quote(fr.name));
    frame_field[fr.name] = f;
    frame_names.push_back(fr.name);
    const std::string link = resolve(fr.link, join(f, "link"), "link");
    Frame out;
    out.name = fr.name;
    out.link = link;
    out.placement = iso(frame_of_link(link) * transform(fr.origin.xyz, fr.origin.rpy));
    desc.frames.push_back(out);
  }

  std::map<std::string, std::string> loop_field;
  for (std::size_t k = 0; k < m.loops.size(); ++k) {
    const auto& lp = m.loops[k];
    const std::string f = item(join(field, "loops"), k);
    auto it = loop_field.find(lp.name);
    if (it != loop_field.end()) fail(join(f, "name"), "duplicate loop name: also " + it->second, quote(lp.name));
    loop_field[lp.name] = f;
    for (const auto* key : {"frame_a", "frame_b"}) {
      const std::string& nm = std::string(key) == "frame_a" ? lp.frame_a : lp.frame_b;
      if (!frame_field.count(nm)) {
        fail(join(f, key), "no such frame (define it in [[mechanism.frames]])" + did_you_mean(nm, frame_names), quote(nm));
      }
    }
    LoopConstraint out;
    out.name = lp.name;
    out.type = lp.type == "point" ? LoopType::point
               : lp.type == "planar_point" ? LoopType::planar_point
               : lp.type == "axis" ? LoopType::axis
                                   : LoopType::weld;
    out.frame_a = lp.frame_a;
    out.frame_b = lp.frame_b;
    desc.loops.push_back(out);
  }

  std::map<std::string, std::string> spring_field;
  for (std::size_t k = 0; k < m.springs.size(); ++k) {
    const auto& sp = m.springs[k];
    const std::string f = item(join(field, "springs"), k);
    auto it = spring_field.find(sp.name);
    if (it != spring_field.end()) fail(join(f, "name"), "duplicate spring name: also " + it->second, quote(sp.name));
    spring_field[sp.name] = f;
    Spring out;
    out.name = sp.name;
    out.link_a = resolve(sp.link_a, join(f, "link_a"), "link");
    Mat4 T = frame_of_link(out.link_a);
    out.anchor_a = T.topLeftCorner<3, 3>() * sp.anchor_a + T.topRightCorner<3, 1>();
    out.link_b = resolve(sp.link_b, join(f, "link_b"), "link");
    T = frame_of_link(out.link_b);
    out.anchor_b = T.topLeftCorner<3, 3>() * sp.anchor_b + T.topRightCorner<3, 1>();
    if (out.link_a == out.link_b) {
      fail(join(f, "link_b"), "both anchors are on the same link, so the spring never changes length", quote(sp.link_b));
    }
    out.rate = sp.rate;
    out.free_length = sp.free_length;
    out.preload = sp.preload;
    out.count = sp.count;
    out.pulley_ratio = sp.pulley_ratio;
    desc.springs.push_back(out);
  }

  std::vector<std::string> independent;
  for (const auto& j : desc.joints)
    if (j.type != JointType::fixed && j.mimic_joint.empty()) independent.push_back(j.name);
  for (std::size_t k = 0; k < m.actuated.size(); ++k) {
    const auto& nm = m.actuated[k];
    if (std::find(independent.begin(), independent.end(), nm) == independent.end()) {
      fail(item(join(field, "actuated"), k), "not a joint with its own coordinate" + did_you_mean(nm, independent), quote(nm));
    }
  }
  {
    std::vector<std::string> sorted = m.actuated;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      fail(join(field, "actuated"), "names a joint twice", list_repr(m.actuated));
    }
  }
  if (!desc.loops.empty() && m.actuated.empty()) {
    fail(join(field, "actuated"), "a mechanism with loops must name its actuated joints");
  }
  desc.actuated = m.actuated;
  return desc;
}

// ---- documents ------------------------------------------------------------------------------

// config.MAX_CASE_BYTES, config.MAX_CASE_DEPTH
constexpr std::uintmax_t kMaxCaseBytes = 4u * 1024u * 1024u;
constexpr double kMaxTicks = 1e6;  // schema.MAX_TICKS: controller ticks of one run
constexpr int kMaxCaseDepth = 32;

[[noreturn]] void too_deep(const std::string& source) {
  fail(source, "nests arrays or tables more than " + std::to_string(kMaxCaseDepth) +
                   " deep, too deeply to be a case file");
}

/// The position just after the string (basic, literal, single- or multi-line) that opens at
/// text[i], or the end of its line when it is not closed there (the parser says so). `after_wrap`,
/// when given, receives the offset of each non-ASCII character that follows a line-ending
/// backslash of a multi-line basic string (see toml_safe_text).
std::size_t skip_string(const std::string& text, std::size_t i, std::vector<std::size_t>* after_wrap = nullptr) {
  const char q = text[i];
  const std::size_t n = text.size();
  const bool triple = i + 2 < n && text[i + 1] == q && text[i + 2] == q;
  i += triple ? 3 : 1;
  while (i < n) {
    if (q == '"' && text[i] == '\\') {
      std::size_t j = i + 1;
      if (triple && after_wrap) {
        while (j < n && (text[j] == ' ' || text[j] == '\t' || text[j] == '\r' || text[j] == '\n')) ++j;
        if (j > i + 1 && j < n && static_cast<unsigned char>(text[j]) >= 0x80) after_wrap->push_back(j);
      }
      i = std::max(j, i + 2);
    } else if (!triple && text[i] == '\n') {
      return i;
    } else if (text[i] == q && (!triple || (i + 2 < n && text[i + 1] == q && text[i + 2] == q))) {
      if (!triple) return i + 1;
      i += 3;
      for (int extra = 0; extra < 2 && i < n && text[i] == q; ++extra) ++i;  // """a"""" is 'a"'
      return i;
    } else {
      ++i;
    }
  }
  return n;
}

/// Refuses, before parsing, a dotted key or table header of more than kMaxCaseDepth segments
/// (`a.b.c. ... = 1`): each segment is a table level, and toml++ walks a deep tree recursively (a
/// stack overflow for ~1e5 levels). Outside strings and comments, a run of key characters and
/// dots holds more than one dot only in a dotted key (a float or a date has one).
void check_dotted_depth(const std::string& text, const std::string& source) {
  int dots = 0;
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
      dots = 0;
    } else if (c == '"' || c == '\'') {
      i = skip_string(text, i) - 1;
    } else if (c == '.') {
      if (++dots > kMaxCaseDepth) too_deep(source);
    } else if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '+' || c == ' ' ||
                 c == '\t')) {
      dots = 0;
    }
  }
}

/// A place in a document where toml++ 3.3.0 would break one of its own assumptions (see
/// toml_hazard): what it is and the offset of the character.
struct TomlHazard {
  enum Kind { header_without_key, brace_for_value, non_ascii } kind;
  std::size_t at;
  bool array_header;  // header_without_key: after `[[`
};

/// The first place where toml++ 3.3.0, reading `text`, would break an assumption of its own: an
/// abort in a debug build (a failed assertion), undefined behaviour in a release one.
/// - header_without_key: a table header whose `[` or `[[` (and the spaces or tabs after it) is
///   followed by a character that starts no key (`[.`, `[=`, `[[[1]]]`, `[` alone on its line):
///   parse_table_header hands it to parse_key, which asserts that a key starts there (fixed after
///   3.4.0, marzer/tomlplusplus#301).
/// - brace_for_value: a `}` where an array expects a value (`x = [1, }`): parse_array hands it
///   to parse_value, which asserts that no value terminator starts a value.
/// - non_ascii: a character that is not ASCII outside strings and comments (`x = 1é`, `é = 1`).
///   toml++ asks is_horizontal_whitespace about it, and for most of U+00A1-U+0499, U+2C6E-U+3067
///   and U+FC06-U+FEFE that function reaches __builtin_unreachable (fixed after 3.4.0,
///   marzer/tomlplusplus#305). Valid TOML holds such characters only in strings and comments.
/// Outside strings and comments, a `[` first on its line (after spaces or tabs) and outside the
/// arrays and inline tables of values opens a header. toml++ reaches the hazard only when the text
/// before it is valid TOML; parse() leaves the rest to toml++.
std::optional<TomlHazard> toml_hazard(const std::string& text) {
  auto blank = [](char c) { return c == ' ' || c == '\t'; };
  auto starts_key = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '"' || c == '\'';
  };
  const std::size_t n = text.size();
  std::size_t i = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // toml++ skips a byte-order mark
  std::vector<char> open;   // the arrays ('[') and inline tables ('{') of values open here
  bool want_value = false;  // the innermost array expects a value (after its `[` or a comma)
  bool line_start = true;   // nothing but spaces or tabs since the line break (outside values)
  bool header = false;      // on a table header's line
  while (i < n) {
    const char c = text[i];
    if (c == '\n') {
      if (open.empty()) line_start = true, header = false;
      ++i;
    } else if (blank(c) || c == '\r') {
      ++i;
    } else if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
    } else if (static_cast<unsigned char>(c) >= 0x80) {
      return TomlHazard{TomlHazard::non_ascii, i, false};
    } else if (c == '"' || c == '\'') {
      i = skip_string(text, i);
      line_start = want_value = false;
    } else if (c == '}' && want_value && !open.empty() && open.back() == '[') {
      return TomlHazard{TomlHazard::brace_for_value, i, false};
    } else if (c == '[' && open.empty() && line_start) {
      std::size_t j = i + 1;
      bool spaced = false;
      for (; j < n && blank(text[j]); ++j) spaced = true;
      const bool array = j < n && text[j] == '[' && !spaced;  // `[ [` is refused by toml++ itself
      if (array)
        for (++j; j < n && blank(text[j]);) ++j;
      if (j < n && text[j] != ']' && !(text[j] == '[' && spaced) && !starts_key(text[j])) {
        return TomlHazard{TomlHazard::header_without_key, j, array};
      }
      header = true;
      line_start = false;
      i = j;
    } else {
      line_start = false;
      if (!header && (c == '[' || c == '{')) {
        open.push_back(c);
        want_value = c == '[';
      } else if (!header && (c == ']' || c == '}') && !open.empty()) {
        open.pop_back();
        want_value = false;
      } else {
        want_value = c == ',' && !open.empty() && open.back() == '[';
      }
      ++i;
    }
  }
  return std::nullopt;
}

/// `text` as toml++ 3.3.0 can read it without breaking its assumptions when it is valid TOML: a
/// non-ASCII character right after the spaces and line breaks that a line-ending backslash of a
/// multi-line basic string trims (`"""a\` at the end of a line, `é"""` on the next) is handed to
/// toml++ as its \u escape. toml++ would otherwise ask is_horizontal_whitespace about it (see
/// toml_hazard); the escape is the same character, so the string reads the same.
std::string toml_safe_text(const std::string& text) {
  std::vector<std::size_t> wraps;
  for (std::size_t i = 0; i < text.size();) {
    if (text[i] == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text[i] == '"' || text[i] == '\'') {
      i = skip_string(text, i, &wraps);
    } else {
      ++i;
    }
  }
  if (wraps.empty()) return text;
  std::string out;
  out.reserve(text.size() + 10 * wraps.size());
  std::size_t from = 0;
  for (const std::size_t at : wraps) {
    const unsigned char c = static_cast<unsigned char>(text[at]);
    const int len = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (len == 0 || at + static_cast<std::size_t>(len) > text.size()) continue;  // not UTF-8: toml++ says so
    unsigned long code = len == 2 ? c & 0x1Fu : len == 3 ? c & 0x0Fu : c & 0x07u;
    bool whole = true;
    for (int k = 1; k < len; ++k) {
      const unsigned char cont = static_cast<unsigned char>(text[at + static_cast<std::size_t>(k)]);
      whole = whole && (cont & 0xC0) == 0x80;
      code = (code << 6) | (cont & 0x3Fu);
    }
    if (!whole || code < 0x80 || (code >= 0xD800 && code <= 0xDFFF) || code > 0x10FFFF) continue;
    char escape[16];
    std::snprintf(escape, sizeof escape, code > 0xFFFF ? "\\U%08lX" : "\\u%04lX", code);
    out.append(text, from, at - from).append(escape);
    from = at + static_cast<std::size_t>(len);
  }
  return out.append(text, from, std::string::npos);
}

/// config._nesting_depth: the deepest nesting of tables and arrays (the document is depth 1),
/// without recursion.
int nesting_depth(const toml::table& doc) {
  int deepest = 0;
  std::vector<std::pair<const toml::node*, int>> stack{{&doc, 1}};
  while (!stack.empty()) {
    const auto [node, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    if (d > kMaxCaseDepth + 1) continue;
    if (const toml::table* t = node->as_table()) {
      for (auto&& [k, v] : *t)
        if (v.is_table() || v.is_array()) stack.emplace_back(&v, d + 1);
    } else if (const toml::array* a = node->as_array()) {
      for (auto&& v : *a)
        if (v.is_table() || v.is_array()) stack.emplace_back(&v, d + 1);
    }
  }
  return deepest;
}

/// "U+00E9" for the (UTF-8) character at text[at], "byte 0xNN" when it is not one, "'c'" for a
/// printable ASCII one, "the end of the line" for a line break (the message stays ASCII).
std::string shown_character(const std::string& text, std::size_t at) {
  const unsigned char c = static_cast<unsigned char>(text[at]);
  if (c == '\n' || (c == '\r' && at + 1 < text.size() && text[at + 1] == '\n')) return "the end of the line";
  if (c > 0x20 && c < 0x7F) return std::string("'") + static_cast<char>(c) + "'";
  const int len = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 1;
  unsigned long code = len == 2 ? c & 0x1Fu : len == 3 ? c & 0x0Fu : c & 0x07u;
  bool whole = len > 1 && at + static_cast<std::size_t>(len) <= text.size();
  for (int k = 1; whole && k < len; ++k) {
    const unsigned char cont = static_cast<unsigned char>(text[at + static_cast<std::size_t>(k)]);
    whole = (cont & 0xC0) == 0x80;
    code = (code << 6) | (cont & 0x3Fu);
  }
  char buf[16];
  if (whole) {
    std::snprintf(buf, sizeof buf, "U+%04lX", code);
  } else {
    std::snprintf(buf, sizeof buf, "byte 0x%02x", static_cast<unsigned>(c));
  }
  return buf;
}

/// The line and column of text[at], both from 1, columns counting characters (as toml++ and tomllib).
std::pair<std::size_t, std::size_t> line_and_column(const std::string& text, std::size_t at) {
  std::size_t line = 1, column = 1;
  for (std::size_t k = 0; k < at; ++k) {
    if (text[k] == '\n') {
      ++line;
      column = 1;
    } else if ((static_cast<unsigned char>(text[k]) & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++column;
    }
  }
  return {line, column};
}

[[noreturn]] void not_toml(const std::string& source, const std::string& what, std::size_t line, std::size_t column) {
  fail(source, "is not valid TOML: " + what + " (line " + std::to_string(line) + ", column " + std::to_string(column) +
                   ")");
}

/// toml++ on `text`, or a one-line ConfigError naming `source`, the line and the column. A text
/// with a toml_hazard is refused without toml++ reading the hazard: at toml++'s own first error
/// when that comes before the hazard (toml++ reads the text up to it, the hazard excluded), else
/// at the hazard.
toml::table parse_toml(const std::string& text, const std::string& source) {
  const std::string safe = toml_safe_text(text);
  const std::optional<TomlHazard> hazard = toml_hazard(safe);
  const auto hazard_at = hazard ? line_and_column(safe, hazard->at) : std::pair<std::size_t, std::size_t>{};
  try {
    if (!hazard) return toml::parse(safe, source);
    (void)toml::parse(std::string_view(safe).substr(0, hazard->at), source);
  } catch (const toml::parse_error& e) {
    if (e.description().find("TOML_MAX_NESTED_VALUES") != std::string_view::npos) too_deep(source);
    const std::pair<std::size_t, std::size_t> at{e.source().begin.line, e.source().begin.column};
    // toml++ says where the text up to the hazard ends early (end-of-file, EOF): not an error of its own
    const bool cut = hazard && (e.description().find("end-of-file") != std::string_view::npos ||
                                e.description().find("EOF") != std::string_view::npos);
    if (!hazard || (at < hazard_at && !cut)) not_toml(source, one_line(e.description()), at.first, at.second);
  }
  std::string what;
  switch (hazard->kind) {
    case TomlHazard::header_without_key:
      what = "a table header must start with a key, saw " + shown_character(safe, hazard->at) + " after '" +
             (hazard->array_header ? "[[" : "[") + "'";
      break;
    case TomlHazard::brace_for_value:
      what = "expected a value or ']' in an array, saw '}'";
      break;
    case TomlHazard::non_ascii:
      what = "the character " + shown_character(safe, hazard->at) +
             " is not ASCII: outside strings and comments TOML allows only ASCII";
      break;
  }
  not_toml(source, what, hazard_at.first, hazard_at.second);
}

toml::table parse(const std::string& text, const std::string& source) {
  check_dotted_depth(text, source);
  toml::table doc = parse_toml(text, source);
  if (nesting_depth(doc) > kMaxCaseDepth) too_deep(source);
  return doc;
}

/// A text given as a string: at most kMaxCaseBytes, as a file (read_file), else ConfigError(source).
void check_text_size(const std::string& text, const std::string& source) {
  if (text.size() > kMaxCaseBytes) {
    fail(source.empty() ? "case" : source, "is " + std::to_string(text.size()) +
                                               " bytes, more than a case file can be (" +
                                               std::to_string(kMaxCaseBytes) + " bytes)");
  }
}

/// config.read_regular_file: a regular file of at most kMaxCaseBytes, else ConfigError("case").
std::string read_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) fail("case", "file not found", quote(path));
  if (std::filesystem::is_directory(status)) fail("case", "is a folder, not a file", quote(path));
  if (!std::filesystem::is_regular_file(status)) fail("case", "is not a regular file (a device, pipe or socket)", quote(path));
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) fail("case", "cannot be read: " + ec.message(), quote(path));
  if (size > kMaxCaseBytes) {
    fail("case", "is " + std::to_string(size) + " bytes, more than such a file can be (" +
                     std::to_string(kMaxCaseBytes) + " bytes)", quote(path));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("case", "cannot be read", quote(path));
  std::string text;
  text.resize(static_cast<std::size_t>(size));
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size || in.peek() != std::char_traits<char>::eof()) {
    fail("case", "changed while being read", quote(path));
  }
  return text;
}

MechanismDescription description_of(const toml::table& doc) {
  const toml::node* m = doc.get("mechanism");
  if (!m) fail("mechanism", "is required");
  return build_description(read_mechanism(*m, "mechanism"), "mechanism");
}

MechanismModel model_of(MechanismDescription desc) {
  try {
    return MechanismModel(std::move(desc));
  } catch (const ConfigError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    fail("mechanism", e.what());
  }
}

// ---- [control] --------------------------------------------------------------------------------

std::vector<double> numbers(const toml::node& n, const std::string& f, std::size_t max_len, double lo, Lo lo_kind) {
  const toml::array& a = array_of(n, f, 1, max_len);
  std::vector<double> out;
  for (std::size_t k = 0; k < a.size(); ++k) out.push_back(number(*a.get(k), item(f, k), lo, kMaxAbs, lo_kind));
  return out;
}

std::vector<std::string> names_list(const toml::node& n, const std::string& f, std::size_t max_len) {
  const toml::array& a = array_of(n, f, 1, max_len);
  std::vector<std::string> out;
  for (std::size_t k = 0; k < a.size(); ++k) out.push_back(name(*a.get(k), item(f, k)));
  return out;
}

/// schema.Control: the same keys, bounds and defaults; the checks across tables (sizes, joint and
/// frame names) as schema._cross_checks, in the same order, so both readers name the same field.
ControlConfig read_control(const toml::node& n, const MechanismModel& model) {
  const std::string f = "control";
  const auto& t = table_of(n, f);
  const std::vector<std::string> decoupled{"k"};
  const std::vector<std::string> reactionless{"balancing_joints", "cancel", "integrator", "damping",
                                              "max_rate", "home_gain", "limit_gain", "task_frame", "task_rows"};
  const std::vector<std::string> all{"kind", "balancing_joints", "cancel", "integrator", "rate_hz", "damping", "max_rate",
                               "home_gain", "limit_gain", "task_frame", "task_rows", "kp", "kd", "torque_limit", "k",
                                     "max_speed", "tolerance"};
  allow_keys(t, f, all);
  ControlConfig c;
  // the table's own fields (types, ranges), in the Python model's order
  const std::string kind =
      choice(required(t, "kind", f), join(f, "kind"), {"reactionless", "computed_torque", "decoupled", "passive"});
  c.kind = kind == "computed_torque" ? ControlKind::computed_torque
           : kind == "decoupled"     ? ControlKind::decoupled
           : kind == "passive"       ? ControlKind::passive
                                     : ControlKind::reactionless;
  if (auto x = get(t, "balancing_joints")) c.balancing_joints = names_list(*x, join(f, "balancing_joints"), kMaxJoints);
  if (auto x = get(t, "cancel")) {
    const std::string fc = join(f, "cancel");
    const toml::array& a = array_of(*x, fc, 1, 9);
    c.cancel.clear();
    for (std::size_t k = 0; k < a.size(); ++k) {
      c.cancel.push_back(choice(*a.get(k), item(fc, k), {"moment", "force", "both", "moment_x", "moment_y",
                                                         "moment_z", "force_x", "force_y", "force_z"}));
    }
  }
  if (auto x = get(t, "integrator")) c.integrator = choice(*x, join(f, "integrator"), {"euler", "rk4"});
  if (auto x = get(t, "rate_hz")) c.rate_hz = number(*x, join(f, "rate_hz"), 1.0, 1e6);
  if (auto x = get(t, "damping")) {
    c.damping = number(*x, join(f, "damping"), 0.0, kMaxAbs, Lo::gt);
    if (!(c.damping < 1.0)) fail(join(f, "damping"), "must be < 1", *x);
  }
  if (auto x = get(t, "max_rate")) c.max_rate = number(*x, join(f, "max_rate"), 0.0, kMaxAbs, Lo::gt);
  if (auto x = get(t, "home_gain")) c.home_gain = number(*x, join(f, "home_gain"), 0.0);
  if (auto x = get(t, "limit_gain")) c.limit_gain = number(*x, join(f, "limit_gain"), 0.0);
  if (auto x = get(t, "task_frame")) c.task_frame = name(*x, join(f, "task_frame"));
  if (auto x = get(t, "task_rows")) {
    const std::string fr = join(f, "task_rows");
    const toml::array& a = array_of(*x, fr, 1, 8);
    c.task_rows.clear();
    for (std::size_t k = 0; k < a.size(); ++k) {
      c.task_rows.push_back(
          choice(*a.get(k), item(fr, k), {"all", "linear", "angular", "v_x", "v_y", "v_z", "w_x", "w_y", "w_z"}));
    }
  }
  std::vector<std::vector<double>*> per_joint{&c.kp, &c.kd, &c.torque_limit, &c.k};
  const char* per_joint_keys[] = {"kp", "kd", "torque_limit", "k"};
  for (std::size_t i = 0; i < per_joint.size(); ++i) {
    if (auto x = get(t, per_joint_keys[i])) *per_joint[i] = numbers(*x, join(f, per_joint_keys[i]), kMaxJoints, 0.0, Lo::gt);
  }
  if (auto x = get(t, "max_speed")) c.max_speed = number(*x, join(f, "max_speed"), 0.0, kMaxAbs, Lo::gt);
  if (auto x = get(t, "tolerance")) {
    const std::string ft = join(f, "tolerance");
    const auto& tt = table_of(*x, ft);
    allow_keys(tt, ft, {"residual", "floor", "position", "orientation", "joint"});
    const std::pair<const char*, double*> keys[] = {
        {"residual", &c.tolerance.residual}, {"floor", &c.tolerance.floor}, {"position", &c.tolerance.position},
        {"orientation", &c.tolerance.orientation}, {"joint", &c.tolerance.joint}};
    for (const auto& k : keys)
      if (auto y = get(tt, k.first)) *k.second = number(*y, join(ft, k.first), 0.0, kMaxAbs, Lo::gt);
  }
  // the table's own rules across its fields (schema.Control._rules)
  if (c.kind == ControlKind::passive) {  // no controller: only the tick rate of the log
    for (auto&& [k, v] : t) {            // toml++ keeps the keys sorted, as Python's sorted()
      const std::string key(k.str());
      if (key != "kind" && key != "rate_hz") fail(join(f, key), "is not for kind = 'passive' (no controller: only rate_hz)", v);
    }
    return c;
  }
  const std::string fb = join(f, "balancing_joints");
  for (std::size_t k = 0; k < c.balancing_joints.size(); ++k) {
    const auto begin = c.balancing_joints.begin();
    if (std::find(begin, begin + static_cast<long>(k), c.balancing_joints[k]) != begin + static_cast<long>(k)) {
      fail(item(fb, k), "is listed twice", quote(c.balancing_joints[k]));
    }
  }
  for (const std::string& key : all) {  // in the Python model's field order
    const toml::node* v = t.get(key);
    if (!v) continue;
    const bool is_decoupled = std::find(decoupled.begin(), decoupled.end(), key) != decoupled.end();
    const bool is_reactionless = std::find(reactionless.begin(), reactionless.end(), key) != reactionless.end();
    if ((is_decoupled && c.kind != ControlKind::decoupled) || (is_reactionless && c.kind != ControlKind::reactionless)) {
      fail(join(f, key), std::string("is only for kind = '") + (is_decoupled ? "decoupled" : "reactionless") + "'", *v);
    }
  }
  if (c.kind == ControlKind::reactionless && !get(t, "balancing_joints") && !get(t, "task_frame")) {
    fail(fb, "is required for kind = 'reactionless' (or task_frame: the operational-space mode)");
  }
  if (c.kind != ControlKind::reactionless) {
    for (const char* key : {"kp", "kd"}) {
      if (!get(t, key)) fail(join(f, key), "is required for kind = '" + kind + "'");
    }
  }
  if (get(t, "kp") && !get(t, "kd")) fail(join(f, "kd"), "is required with kp (the computed-torque stage)");
  if (get(t, "kd") && !get(t, "kp")) fail(join(f, "kp"), "is required with kd (the computed-torque stage)");
  if (get(t, "task_rows") && !get(t, "task_frame")) {
    fail(join(f, "task_rows"), "is for the operational-space mode: give task_frame", *get(t, "task_rows"));
  }
  // against the mechanism (schema._cross_checks)
  std::vector<std::string> actuated;
  for (int i : model.actuated_coordinates()) actuated.push_back(model.coordinate_name(i));
  std::string actuated_list;
  for (const auto& a : actuated) actuated_list += (actuated_list.empty() ? "" : ", ") + a;
  for (std::size_t i = 0; i < per_joint.size(); ++i) {
    if (!per_joint[i]->empty() && per_joint[i]->size() != actuated.size()) {
      fail(join(f, per_joint_keys[i]),
           "must have " + std::to_string(actuated.size()) + " values (one per actuated joint: " + actuated_list + ")",
           *get(t, per_joint_keys[i]));
    }
  }
  for (std::size_t k = 0; k < c.balancing_joints.size(); ++k) {
    const auto& nm = c.balancing_joints[k];
    if (std::find(actuated.begin(), actuated.end(), nm) == actuated.end()) {
      fail(item(fb, k), "is not an actuated joint" + did_you_mean(nm, actuated), quote(nm));
    }
  }
  if (c.kind == ControlKind::reactionless && c.task_frame.empty() && !c.balancing_joints.empty() &&
      c.balancing_joints.size() == actuated.size()) {
    fail(fb, "lists every actuated joint: none is left to follow [trajectory] (keep one out, or give task_frame: "
             "the operational-space mode)", *get(t, "balancing_joints"));
  }
  if (!c.task_frame.empty() && model.frame_index(c.task_frame) < 0) {
    std::vector<std::string> frames;
    for (int k = 0; k < model.num_frames(); ++k) frames.push_back(model.frame(k).name);
    fail(join(f, "task_frame"), "is not a frame of the mechanism" + did_you_mean(c.task_frame, frames),
         *get(t, "task_frame"));
  }
  return c;
}

// ---- [trajectory] of a mechanism case (schema.ChainTrajectory) --------------------------------

std::vector<double> joint_values(const toml::node& n, const std::string& f) {
  const toml::array& a = array_of(n, f, 1, kMaxJoints);
  std::vector<double> out;
  for (std::size_t k = 0; k < a.size(); ++k) out.push_back(number(*a.get(k), item(f, k)));
  return out;
}

/// A speed or rpm: one number (every actuated joint) or one per actuated joint (tables.Speeds).
std::vector<double> speeds(const toml::node& n, const std::string& f, bool& scalar) {
  scalar = !n.is_array();
  if (scalar) return {number(n, f)};
  return joint_values(n, f);
}

TrajectoryConfig read_trajectory(const toml::node& n, const MechanismModel& model) {
  const std::string f = "trajectory";
  const auto& t = table_of(n, f);
  // the laws of the Python layer that this reader cannot run: refused by name, before their own
  // keys would read as unknown ones (a planned motion is an optimisation, not a time law)
  if (auto x = get(t, "law"); x && x->is_string()) {
    const std::string law = x->as_string()->get();
    if (law == "min_shaking") {
      fail(join(f, "law"),
           "'min_shaking' is a motion planned by the Python layer (mechbal.plan); this reader runs "
           "quintic, cubic and constant_speed: plan it with `mechbal run` (motion.npz) or give one of those",
           *x);
    }
  }
  allow_keys(t, f, {"law", "start", "end", "duration", "speed", "rpm", "revolutions", "samples", "initial_guess",
                    "branch"});
  TrajectoryConfig tr;
  tr.present = true;
  std::string law = "quintic";
  if (auto x = get(t, "law")) law = choice(*x, join(f, "law"), {"quintic", "cubic", "constant_speed"});
  tr.law = law == "cubic" ? TimeLaw::cubic : TimeLaw::quintic;
  tr.constant_speed = law == "constant_speed";
  // the fields, in the Python model's order (schema.ChainTrajectory), then its checks across them
  tr.start = joint_values(required(t, "start", f), join(f, "start"));
  if (auto x = get(t, "end")) tr.end = joint_values(*x, join(f, "end"));
  std::optional<double> duration, revolutions;
  if (auto x = get(t, "duration")) duration = number(*x, join(f, "duration"), 1e-3, 1e6);
  bool speed_scalar = false, rpm_scalar = false;
  std::vector<double> speed, rpm;
  if (auto x = get(t, "speed")) speed = speeds(*x, join(f, "speed"), speed_scalar);
  if (auto x = get(t, "rpm")) rpm = speeds(*x, join(f, "rpm"), rpm_scalar);
  if (auto x = get(t, "revolutions")) revolutions = number(*x, join(f, "revolutions"), 0.0, 1e6, Lo::gt);
  if (auto x = get(t, "samples")) tr.samples = static_cast<int>(integer(*x, join(f, "samples"), 3, 1000000));
  if (auto x = get(t, "initial_guess")) tr.initial_guess = joint_values(*x, join(f, "initial_guess"));
  if (auto x = get(t, "branch")) tr.branch = choice(*x, join(f, "branch"), {"open", "crossed"});
  const std::size_t na = static_cast<std::size_t>(model.num_actuated());
  if (tr.constant_speed) {
    if (get(t, "end")) {
      fail(join(f, "end"), "is for the rest-to-rest laws (quintic, cubic); a constant-speed motion has start, speed "
                           "or rpm, and duration or revolutions", *get(t, "end"));
    }
    const bool has_speed = get(t, "speed") != nullptr, has_rpm = get(t, "rpm") != nullptr;
    if (has_speed && has_rpm) fail(join(f, "rpm"), "give speed (rad/s) or rpm, not both", *get(t, "rpm"));
    if (!has_speed && !has_rpm) fail(join(f, "speed"), "law = 'constant_speed' needs speed (rad/s) or rpm");
    if (duration && revolutions) fail(join(f, "revolutions"), "give duration or revolutions, not both", *get(t, "revolutions"));
    if (!duration && !revolutions) fail(join(f, "duration"), "law = 'constant_speed' needs duration (s) or revolutions");
    const bool scalar = has_speed ? speed_scalar : rpm_scalar;
    tr.speed = has_speed ? speed : rpm;
    if (has_rpm) {
      for (double& w : tr.speed) w *= 2.0 * 3.141592653589793 / 60.0;
    }
    if (scalar) tr.speed.assign(tr.start.size(), tr.speed[0]);
    if (revolutions) {
      double top = 0.0;
      for (double w : tr.speed) top = std::max(top, std::abs(w));
      if (top == 0.0) fail(join(f, "revolutions"), "needs a non-zero speed (every speed is 0)", *get(t, "revolutions"));
      tr.revolutions = *revolutions;
      tr.duration = *revolutions * 2.0 * 3.141592653589793 / top;
      if (!(tr.duration >= 1e-3 && tr.duration <= 1e6)) {
        fail(join(f, "revolutions"), "gives a duration outside 0.001 .. 1000000 s", *get(t, "revolutions"));
      }
    } else {
      tr.duration = *duration;
    }
    if (scalar) tr.speed.assign(na, tr.speed[0]);
  } else {
    for (const char* key : {"speed", "rpm", "revolutions"}) {
      if (auto x = get(t, key)) fail(join(f, key), "is for law = 'constant_speed' (law is '" + law + "')", *x);
    }
    if (!get(t, "end")) fail(join(f, "end"), "law = '" + law + "' needs end");
    if (!duration) fail(join(f, "duration"), "law = '" + law + "' needs duration");
    tr.duration = *duration;
  }
  for (const char* key : {"start", "end", "speed", "rpm"}) {
    const toml::node* x = get(t, key);
    if (!x || !x->is_array()) continue;
    if (x->as_array()->size() != na) fail(join(f, key), "must have " + std::to_string(na) + " values (one per actuated joint)", *x);
  }
  if (model.is_closed()) {
    const std::size_t dof = static_cast<std::size_t>(model.dof());
    if (!tr.initial_guess.empty() && tr.initial_guess.size() != dof && tr.initial_guess.size() != na) {
      fail(join(f, "initial_guess"),
           "must have " + std::to_string(dof) + " values (every joint coordinate) or " + std::to_string(na) +
               " (the actuated joints)",
           *get(t, "initial_guess"));
    }
  } else {
    for (const char* key : {"initial_guess", "branch"}) {
      if (auto x = get(t, key)) fail(join(f, key), "is for closed mechanisms (with [[mechanism.loops]]); this one has no loop", *x);
    }
  }
  return tr;
}

LoadedCase case_of(const toml::table& doc) {
  std::string case_name, kind;
  if (const toml::node* h = doc.get("case")) {
    if (h->is_table()) {
      if (auto nm = h->as_table()->get("name"); nm && nm->is_string()) case_name = nm->as_string()->get();
      if (auto k = h->as_table()->get("kind"); k && k->is_string()) kind = k->as_string()->get();
    }
  }
  const bool chain = kind.empty() || kind == "mechanism" || kind == "serial_chain";
  // the tables of the format (schema.SerialChainCase): a misspelled one ([contrl]) is an error
  if (chain) {
    allow_keys(doc, "", {"case", "mechanism", "trajectory", "balance", "control"});
    if (const toml::node* h = doc.get("case"); h && h->is_table()) allow_keys(*h->as_table(), "case", {"name", "kind", "title"});
  }
  MechanismModel model = model_of(description_of(doc));
  ControlConfig control;
  if (const toml::node* c = doc.get("control")) control = read_control(*c, model);
  TrajectoryConfig trajectory;
  if (chain) {
    if (const toml::node* t = doc.get("trajectory")) trajectory = read_trajectory(*t, model);
    // bounded work before a run starts (schema.MAX_TICKS): duration x rate_hz controller ticks
    if (doc.get("control") && trajectory.present) {
      const double ticks = trajectory.duration * control.rate_hz;
      if (ticks > kMaxTicks) {
        fail("control.rate_hz", "duration x rate_hz must be <= 1000000 ticks (a run of " +
                                    float_repr(trajectory.duration) + " s)", float_repr(ticks));
      }
    }
  }
  return LoadedCase{std::move(model), std::move(control), std::move(trajectory), std::move(case_name)};
}

}  // namespace

MechanismDescription mechanism_description_from_string(const std::string& toml_text, const std::string& source) {
  check_text_size(toml_text, source);
  return description_of(parse(toml_text, source));
}

MechanismModel mechanism_from_string(const std::string& toml_text, const std::string& source) {
  return model_of(mechanism_description_from_string(toml_text, source));
}

MechanismModel load_mechanism(const std::string& path) { return mechanism_from_string(read_file(path), path); }

LoadedCase case_from_string(const std::string& toml_text, const std::string& source) {
  check_text_size(toml_text, source);
  return case_of(parse(toml_text, source));
}

LoadedCase load_case(const std::string& path) { return case_from_string(read_file(path), path); }

ControlConfig load_control(const std::string& path, const MechanismModel& model) {
  const toml::table doc = parse(read_file(path), path);
  const toml::node* c = doc.get("control");
  if (!c) fail("control", "is required");
  return read_control(*c, model);
}

}  // namespace mechbal
