// SPDX-License-Identifier: MIT
// A small JSON writer for msgraphs_collab's --summary (no new dependency): objects, arrays,
// strings (escaped), numbers (non-finite ones written as null), booleans and null, indented
// two spaces. The caller nests Begin/End correctly; keys are given before every object member.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace msgraphs::tools::collab {

class JsonWriter {
 public:
  void BeginObject() { Open('{'); }
  void EndObject() { Close('}'); }
  void BeginArray() { Open('['); }
  void EndArray() { Close(']'); }
  /// The next value's key inside an object.
  void Key(std::string_view key);
  void String(std::string_view s);
  void Number(double v);  ///< %.9g; NaN and infinities as null
  void Integer(std::uint64_t v);
  void Integer(std::int64_t v);
  void Bool(bool v);
  void Null();

  // Key and value in one.
  void Field(std::string_view key, std::string_view s) { Key(key), String(s); }
  void Field(std::string_view key, const char* s) { Key(key), String(s); }
  void Field(std::string_view key, double v) { Key(key), Number(v); }
  void Field(std::string_view key, std::uint64_t v) { Key(key), Integer(v); }
  void Field(std::string_view key, std::uint32_t v) { Key(key), Integer(std::uint64_t{v}); }
  void Field(std::string_view key, int v) { Key(key), Integer(std::int64_t{v}); }
  void Field(std::string_view key, bool v) { Key(key), Bool(v); }
  void Field(std::string_view key, std::optional<double> v) {
    Key(key);
    v ? Number(*v) : Null();
  }
  void FieldNull(std::string_view key) { Key(key), Null(); }

  const std::string& text() const { return out_; }

 private:
  void Open(char c);
  void Close(char c);
  void BeforeValue();
  void Quoted(std::string_view s);
  void Indent();
  std::string out_;
  std::vector<bool> first_;  ///< per open container: no member written yet
  bool after_key_ = false;
};

}  // namespace msgraphs::tools::collab
