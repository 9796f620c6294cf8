// SPDX-License-Identifier: MIT
// The node's configuration file format: INI-like sections of `key = value` lines.
//
//   # comment (also after a value: "port = 2368  # data port")
//   [section]
//   key = value with spaces
//
// Parsing keeps every entry with its line number so that validation can name the line; the
// reader then marks each entry it uses, and any left unused is reported: a misspelt key is an
// error, never silently ignored.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace msgraphs::runtime::config {

struct KeyValueEntry {
  std::string section, key, value;
  int line = 0;
  mutable bool used = false;
};

struct KeyValueFile {
  std::string name;  ///< file name, for messages
  std::vector<KeyValueEntry> entries;

  /// The entry `section.key`, or nullptr. Marks it used.
  const KeyValueEntry* Find(const std::string& section, const std::string& key) const;
};

/// Parses `text`; on a syntax error returns false with "name:line: reason" in `error`.
bool ParseKeyValueText(const std::string& text,
                       const std::string& name,
                       KeyValueFile& out,
                       std::string& error);

}  // namespace msgraphs::runtime::config
