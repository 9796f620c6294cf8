// SPDX-License-Identifier: MIT
#include "json_writer.hpp"

#include <cmath>
#include <cstdio>

namespace msgraphs::tools::collab {

void JsonWriter::Indent() {
  out_ += '\n';
  out_.append(2 * first_.size(), ' ');
}

void JsonWriter::BeforeValue() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (first_.empty()) return;  // the top-level value
  if (!first_.back()) out_ += ',';
  first_.back() = false;
  Indent();
}

void JsonWriter::Open(char c) {
  BeforeValue();
  out_ += c;
  first_.push_back(true);
}

void JsonWriter::Close(char c) {
  const bool empty = first_.back();
  first_.pop_back();
  if (!empty) Indent();
  out_ += c;
  if (first_.empty()) out_ += '\n';
}

void JsonWriter::Key(std::string_view key) {
  BeforeValue();
  Quoted(key);
  out_ += ": ";
  after_key_ = true;
}

void JsonWriter::String(std::string_view s) {
  BeforeValue();
  Quoted(s);
}

void JsonWriter::Quoted(std::string_view s) {
  out_ += '"';
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '"':
        out_ += "\\\"";
        break;
      case '\\':
        out_ += "\\\\";
        break;
      case '\n':
        out_ += "\\n";
        break;
      case '\t':
        out_ += "\\t";
        break;
      case '\r':
        out_ += "\\r";
        break;
      default:
        if (c < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", c);
          out_ += b;
        } else {
          out_ += ch;
        }
    }
  }
  out_ += '"';
}

void JsonWriter::Number(double v) {
  BeforeValue();
  if (!std::isfinite(v)) {
    out_ += "null";
    return;
  }
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  out_ += b;
}

void JsonWriter::Integer(std::uint64_t v) {
  BeforeValue();
  out_ += std::to_string(v);
}

void JsonWriter::Integer(std::int64_t v) {
  BeforeValue();
  out_ += std::to_string(v);
}

void JsonWriter::Bool(bool v) {
  BeforeValue();
  out_ += v ? "true" : "false";
}

void JsonWriter::Null() {
  BeforeValue();
  out_ += "null";
}

}  // namespace msgraphs::tools::collab
