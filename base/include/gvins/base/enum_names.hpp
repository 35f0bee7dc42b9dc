// The names of an enumeration's values, spelled once: one table per enumeration in its header,
// from which its toString / fromString functions, the YAML readers (YamlReader::choice) and the
// command-line parsers (CommandLine::choice) all work.
//
//   inline constexpr EnumName<ImuGapPolicy> kImuGapPolicyNames[] = {{ImuGapPolicy::Error, "error"},
//                                                                   {ImuGapPolicy::Warn, "warn"}};
//   enumName(kImuGapPolicyNames, ImuGapPolicy::Warn)      -> "warn"
//   enumFromName(kImuGapPolicyNames, "error")             -> ImuGapPolicy::Error
//   enumNameList(kImuGapPolicyNames)                      -> "error or warn"
#pragma once

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <string_view>

namespace gvins {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

/// The name of `value` ("?" if the table lacks it).
template <class E, std::size_t N>
constexpr const char* enumName(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& e : table)
    if (e.value == value) return e.name;
  return "?";
}

/// The value named `name` (exact spelling), nullopt if none is.
template <class E, std::size_t N>
constexpr std::optional<E> enumFromName(const EnumName<E> (&table)[N], std::string_view name) {
  for (const EnumName<E>& e : table)
    if (name == e.name) return e.value;
  return std::nullopt;
}

/// "a, b or c": the names for messages.
template <class E, std::size_t N>
std::string enumNameList(const EnumName<E> (&table)[N]) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) s += std::string(i == 0 ? "" : (i + 1 == N ? " or " : ", ")) + table[i].name;
  return s;
}

/// The names as a set (YamlReader::choice).
template <class E, std::size_t N>
std::set<std::string> enumNameSet(const EnumName<E> (&table)[N]) {
  std::set<std::string> s;
  for (const EnumName<E>& e : table) s.insert(e.name);
  return s;
}

}  // namespace gvins
