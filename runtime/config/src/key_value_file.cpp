// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/config/key_value_file.hpp"

#include <cctype>

namespace msgraphs::runtime::config {

namespace {

std::string Trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

bool IsName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.') return false;
  }
  return true;
}

}  // namespace

const KeyValueEntry* KeyValueFile::Find(const std::string& section, const std::string& key) const {
  for (const KeyValueEntry& e : entries) {
    if (e.section == section && e.key == key) {
      e.used = true;
      return &e;
    }
  }
  return nullptr;
}

bool ParseKeyValueText(const std::string& text,
                       const std::string& name,
                       KeyValueFile& out,
                       std::string& error) {
  out.name = name;
  out.entries.clear();
  std::string section;
  int line_number = 0;
  std::size_t start = 0;
  auto fail = [&](const std::string& why) {
    error = name + ":" + std::to_string(line_number) + ": " + why;
    return false;
  };
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (line.find('\0') != std::string::npos) return fail("NUL byte in the file");
    // A comment starts at '#' at the beginning or after whitespace (paths may contain '#').
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '#' && (i == 0 || std::isspace(static_cast<unsigned char>(line[i - 1])))) {
        line.resize(i);
        break;
      }
    }
    line = Trim(line);
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (line.back() != ']') return fail("section header without ']'");
      section = Trim(line.substr(1, line.size() - 2));
      if (!IsName(section)) return fail("bad section name '" + section + "'");
      continue;
    }
    const std::size_t eq = line.find('=');
    if (eq == std::string::npos) return fail("expected 'key = value'");
    KeyValueEntry entry{section, Trim(line.substr(0, eq)), Trim(line.substr(eq + 1)), line_number};
    if (section.empty()) return fail("'" + entry.key + "' is outside any [section]");
    if (!IsName(entry.key)) return fail("bad key '" + entry.key + "'");
    for (const KeyValueEntry& e : out.entries) {
      if (e.section == section && e.key == entry.key)
        return fail("'" + entry.key + "' repeats line " + std::to_string(e.line));
    }
    out.entries.push_back(std::move(entry));
    if (end == text.size()) break;
  }
  return true;
}

}  // namespace msgraphs::runtime::config
