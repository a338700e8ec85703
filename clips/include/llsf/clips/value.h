// SPDX-License-Identifier: MIT
// Value: a CLIPS value (symbol, string, number, external address, fact, multifield) held by C++,
// for function arguments, slot values and fact queries. The CLIPS headers stay out of sight.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace llsf::clips {

/// A CLIPS value copied out of (or into) an environment. Copyable; owns its text and items.
struct Value {
  enum class Type : std::uint8_t {
    kVoid,        ///< no value (a function without result, an unset slot)
    kSymbol,      ///< `text`
    kString,      ///< `text`
    kInteger,     ///< `integer`
    kFloat,       ///< `real`
    kAddress,     ///< EXTERNAL-ADDRESS: `address` (e.g. a protobuf message of the pool)
    kFact,        ///< FACT-ADDRESS: `integer` holds the fact index
    kMultifield,  ///< `items`
  };

  Type type = Type::kVoid;
  std::string text;
  std::int64_t integer = 0;
  double real = 0.0;
  void* address = nullptr;
  std::vector<Value> items;

  static Value symbol(std::string s);
  static Value string(std::string s);
  static Value integer_value(std::int64_t i);
  static Value float_value(double d);
  static Value external(void* p);
  static Value multifield(std::vector<Value> items);
  /// The symbols TRUE and FALSE.
  static Value boolean(bool b) { return symbol(b ? "TRUE" : "FALSE"); }

  bool is_symbol(std::string_view s) const { return type == Type::kSymbol && text == s; }
  bool is_string(std::string_view s) const { return type == Type::kString && text == s; }
  bool is_number() const { return type == Type::kInteger || type == Type::kFloat; }
  /// The value of an INTEGER or FLOAT as double (0 for anything else).
  double number() const;
  /// CLIPS notation: `abc`, `"a \"b\""`, `3`, `2.5`, `(a b c)` for multifields, `<Pointer>`.
  std::string to_string() const;

  /// Same type and same contents (FLOAT compared exactly).
  friend bool operator==(const Value& a, const Value& b);
};

}  // namespace llsf::clips
