// SPDX-License-Identifier: MIT
// Value: constructors, comparison and CLIPS notation.
#include "llsf/clips/value.h"

#include <charconv>
#include <cstdio>

namespace llsf::clips {

Value Value::symbol(std::string s) {
  Value v;
  v.type = Type::kSymbol;
  v.text = std::move(s);
  return v;
}

Value Value::string(std::string s) {
  Value v;
  v.type = Type::kString;
  v.text = std::move(s);
  return v;
}

Value Value::integer_value(std::int64_t i) {
  Value v;
  v.type = Type::kInteger;
  v.integer = i;
  return v;
}

Value Value::float_value(double d) {
  Value v;
  v.type = Type::kFloat;
  v.real = d;
  return v;
}

Value Value::external(void* p) {
  Value v;
  v.type = Type::kAddress;
  v.address = p;
  return v;
}

Value Value::multifield(std::vector<Value> items) {
  Value v;
  v.type = Type::kMultifield;
  v.items = std::move(items);
  return v;
}

double Value::number() const {
  if (type == Type::kInteger) return static_cast<double>(integer);
  if (type == Type::kFloat) return real;
  return 0.0;
}

std::string Value::to_string() const {
  switch (type) {
    case Type::kVoid:
      return "";
    case Type::kSymbol:
      return text;
    case Type::kString: {
      std::string out = "\"";
      for (char c : text) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
      }
      return out + "\"";
    }
    case Type::kInteger:
      return std::to_string(integer);
    case Type::kFloat: {
      char buf[32];
      auto r = std::to_chars(buf, buf + sizeof buf, real);
      std::string out(buf, r.ptr);
      if (out.find_first_of(".en") == std::string::npos) out += ".0";
      return out;
    }
    case Type::kAddress:
      return "<Pointer>";
    case Type::kFact:
      return "<Fact-" + std::to_string(integer) + ">";
    case Type::kMultifield: {
      std::string out = "(";
      for (std::size_t i = 0; i < items.size(); ++i) {
        if (i > 0) out += ' ';
        out += items[i].to_string();
      }
      return out + ")";
    }
  }
  return "";
}

bool operator==(const Value& a, const Value& b) {
  if (a.type != b.type) return false;
  switch (a.type) {
    case Value::Type::kVoid:
      return true;
    case Value::Type::kSymbol:
    case Value::Type::kString:
      return a.text == b.text;
    case Value::Type::kInteger:
    case Value::Type::kFact:
      return a.integer == b.integer;
    case Value::Type::kFloat:
      return a.real == b.real;
    case Value::Type::kAddress:
      return a.address == b.address;
    case Value::Type::kMultifield:
      return a.items == b.items;
  }
  return false;
}

}  // namespace llsf::clips
