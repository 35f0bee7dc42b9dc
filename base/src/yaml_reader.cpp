#include "gvins/base/yaml_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <vector>

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace gvins {

namespace {
std::int64_t lineOf(const YAML::Mark& m) { return m.line >= 0 ? m.line + 1 : 0; }
}  // namespace

void YamlReader::fail(const YAML::Node& n, const std::string& key, const std::string& what) const {
  throw ParseError(file_, lineOf(n.Mark()), key, what);
}

double YamlReader::number(const YAML::Node& n, const std::string& key, double lo, double hi) const {
  if (!n.IsScalar()) fail(n, key, "'" + key + "' must be a number");
  const double v = get<double>(n, key);
  if (!(v >= lo && v <= hi)) {
    std::ostringstream os;
    os << "'" << key << "' = " << v << " is outside [" << lo << ", " << hi << "]";
    fail(n, key, os.str());
  }
  return v;
}

int YamlReader::integer(const YAML::Node& n, const std::string& key, int lo, int hi) const {
  if (!n.IsScalar()) fail(n, key, "'" + key + "' must be an integer");
  const int v = get<int>(n, key);
  if (v < lo || v > hi) {
    fail(n, key,
         "'" + key + "' = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return v;
}

bool YamlReader::boolean(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(n, key, "'" + key + "' must be true or false");
  return get<bool>(n, key);
}

std::string YamlReader::text(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(n, key, "'" + key + "' must be a string");
  return get<std::string>(n, key);
}

std::string YamlReader::choice(const YAML::Node& n, const std::string& key, const std::set<std::string>& choices) const {
  const std::string v = text(n, key);
  if (choices.count(v)) return v;
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  fail(n, key, "'" + key + "' = '" + v + "' is not one of: " + list);
}

std::vector<double> YamlReader::numbers(const YAML::Node& n, const std::string& key, int size, double lo,
                                        double hi) const {
  if (!n.IsSequence()) fail(n, key, "'" + key + "' must be a list of numbers");
  if (size >= 0 && static_cast<int>(n.size()) != size) {
    fail(n, key, "'" + key + "' must have " + std::to_string(size) + " entries, not " + std::to_string(n.size()));
  }
  if (size < 0 && n.size() == 0) fail(n, key, "'" + key + "' must not be empty");
  std::vector<double> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(number(n[i], key + "[" + std::to_string(i) + "]", lo, hi));
  return out;
}

std::string YamlReader::key(const YAML::Node& k, const std::string& where) const {
  if (!k.IsScalar()) fail(k, where, "keys of '" + where + "' must be plain names");
  return k.Scalar();
}

std::array<bool, kNumSystems> YamlReader::systems(const YAML::Node& n, const std::string& key) const {
  try {
    return parseSystemLetters(text(n, key));
  } catch (const std::invalid_argument& e) {
    fail(n, key, e.what());
  }
}

YAML::Node YamlReader::loadText(const std::string& text, const std::string& name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ParseError(name, lineOf(e.mark), "YAML", e.msg);
  }
}

namespace {
/// Levenshtein distance of two short keys.
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}
}  // namespace

void YamlReader::sections(const YAML::Node& root, const std::set<std::string>& known) const {
  if (!root.IsMap() || root.size() == 0) return;
  std::string list;
  for (const std::string& s : known) list += (list.empty() ? "" : ", ") + s;
  bool any = false;
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string k = key(it->first, "");
    if (known.count(k)) {
      any = true;
      continue;
    }
    // Other tools' sections may share the file; a near miss of a known name is a typo.
    for (const std::string& s : known) {
      if (k.size() <= 64 && editDistance(k, s) <= 2)
        fail(it->first, k, "unknown section '" + k + "' (did you mean '" + s + "'? expected " + list + ")");
    }
  }
  if (!any) {
    const std::string first = key(root.begin()->first, "");
    fail(root.begin()->first, first, "unknown section '" + first + "': the file has none of the sections " + list);
  }
}

std::string YamlReader::readFile(const std::string& path, std::size_t maxBytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ParseError(path, 0, "", "is a directory, not a configuration file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw ParseError(path, 0, "", "cannot open the configuration file");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > maxBytes)
    throw ParseError(path, 0, "", "configuration file of " + std::to_string(size) + " bytes, larger than the limit of " +
                                       std::to_string(maxBytes));
  std::string text;
  char buf[65536];
  while (f.read(buf, sizeof buf) || f.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(f.gcount()));
    if (text.size() > maxBytes)
      throw ParseError(path, 0, "", "configuration larger than the limit of " + std::to_string(maxBytes) + " bytes");
  }
  return text;
}

YAML::Node YamlReader::loadFile(const std::string& path) { return loadText(readFile(path), path); }

std::array<bool, kNumSystems> parseSystemLetters(std::string_view letters) {
  std::array<bool, kNumSystems> out{};
  for (char c : letters) {
    if (c == ',' || c == ' ') continue;
    const auto s = systemFromLetter(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (!s) throw std::invalid_argument(std::string("unknown system letter '") + c + "' (use G R E C J S I)");
    out[systemIndex(*s)] = true;
  }
  return out;
}

}  // namespace gvins
