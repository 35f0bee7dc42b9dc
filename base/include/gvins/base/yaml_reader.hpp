// Typed access to YAML configuration nodes (yaml-cpp) whose errors are gvins::ParseError naming
// the file, the 1-based line and the dotted key ("spp.elevation_mask_deg"). Every YAML options
// reader of the project (SPP, RTK, simulator scenarios, estimator and fusion configs) goes
// through this class, so all of them reject wrong types, out-of-range values and unknown keys the
// same way.
//
//   YamlReader r("rtk.yaml");
//   r.map(root["rtk"], "rtk", {"mode", "ratio"}, [&](const std::string& k, const std::string& full,
//                                                   const YAML::Node& v) {
//     if (k == "ratio") c.ratio = r.number(v, full, 1.0, 100.0);
//     ...
//   });
#pragma once

#include <array>
#include <set>
#include <string>

#include <yaml-cpp/yaml.h>

#include "gvins/base/enum_names.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  /// Throws ParseError(file, line of `n`, key, what).
  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& what) const;

  /// n.as<T>() with a ParseError on a type mismatch.
  template <class T>
  T get(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(n, key, "wrong type for '" + key + "'");
    }
  }

  /// A finite number in [lo, hi].
  double number(const YAML::Node& n, const std::string& key, double lo, double hi) const;
  /// An integer in [lo, hi].
  int integer(const YAML::Node& n, const std::string& key, int lo, int hi) const;
  bool boolean(const YAML::Node& n, const std::string& key) const;
  std::string text(const YAML::Node& n, const std::string& key) const;
  /// One of `choices`.
  std::string choice(const YAML::Node& n, const std::string& key, const std::set<std::string>& choices) const;
  /// One of the named values of an enumeration (enum_names.hpp).
  /// "'key' must be a, b or c, not 'x'" otherwise.
  template <class E, std::size_t N>
  E choice(const YAML::Node& n, const std::string& key, const EnumName<E> (&names)[N]) const {
    const std::string v = text(n, key);
    if (const auto e = enumFromName(names, v)) return *e;
    fail(n, key, "'" + key + "' must be " + enumNameList(names) + ", not '" + v + "'");
  }
  /// A sequence of exactly `size` numbers (size < 0: any length ≥ 1), each in [lo, hi].
  std::vector<double> numbers(const YAML::Node& n, const std::string& key, int size, double lo, double hi) const;
  /// A map key that must be a plain scalar.
  std::string key(const YAML::Node& k, const std::string& where) const;
  /// Letters of satellite systems ("GREC", "G,E"); see parseSystemLetters().
  std::array<bool, kNumSystems> systems(const YAML::Node& n, const std::string& key) const;

  /// Calls f(key, dotted key, value) for each entry of a map, rejecting keys not in `known`.
  template <class F>
  void map(const YAML::Node& n, const std::string& where, const std::set<std::string>& known, F&& f) const {
    if (!n.IsMap()) fail(n, where, "'" + where + "' must be a map");
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string k = key(it->first, where);
      const std::string full = where.empty() ? k : where + "." + k;
      if (!known.count(k)) fail(it->first, full, "unknown key '" + full + "'");
      f(k, full, it->second);
    }
  }
  /// Calls f(system, dotted key, value) for each entry of a map keyed by system letter.
  template <class F>
  void perSystem(const YAML::Node& n, const std::string& where, F&& f) const {
    if (!n.IsMap()) fail(n, where, "'" + where + "' must be a map of system letters");
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string k = key(it->first, where);
      const auto s = k.size() == 1 ? systemFromLetter(k[0]) : std::nullopt;
      if (!s) fail(it->first, where + "." + k, "unknown system '" + k + "' (use G R E C J S I)");
      f(*s, where + "." + k, it->second);
    }
  }

  /// Checks the top-level keys of a configuration file against the `known` sections of a tool: a
  /// non-empty file without any of them, or a key within two edits of a known name ("sp:",
  /// "rkt:"), is an error (a misspelled section would otherwise be ignored silently). Other keys
  /// are sections of other tools sharing the file and are left alone.
  void sections(const YAML::Node& root, const std::set<std::string>& known) const;

  /// The text of a configuration file: ParseError (line 0) for a missing or unreadable file, a
  /// directory, or a file larger than `maxBytes` (checked before reading: a configuration is
  /// small, and yaml-cpp needs about 200 bytes of memory per byte of a long list).
  static std::string readFile(const std::string& path, std::size_t maxBytes = kMaxFileBytes);
  static constexpr std::size_t kMaxFileBytes = 1 << 20;

  /// Loads a YAML document from a file (ParseError with yaml-cpp's line on a syntax error, or on a
  /// missing/unreadable file) or from text (`name` used in errors).
  static YAML::Node loadFile(const std::string& path);
  static YAML::Node loadText(const std::string& text, const std::string& name);

 private:
  std::string file_;
};

/// Parses letters of satellite systems ("GREC", "G,E", spaces allowed); throws
/// std::invalid_argument naming an unknown letter.
std::array<bool, kNumSystems> parseSystemLetters(std::string_view letters);

}  // namespace gvins
