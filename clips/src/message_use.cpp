// SPDX-License-Identifier: MIT
#include "message_use.h"

#include <array>
#include <string_view>
#include <vector>

#include "source_text.h"

namespace llsf::clips::detail {

namespace {

constexpr std::string_view kTemplate = "protobuf-msg";
// Functions that could see or make any fact or construct from a text.
constexpr std::array<std::string_view, 4> kDynamic = {"build", "eval", "facts", "get-fact-list"};

/// One element of a construct's text: a list, a string or another token (a symbol, a number,
/// a variable, a constraint such as ?t&:).
struct Node {
  enum class Kind { kList, kString, kToken } kind = Kind::kToken;
  std::string text;  ///< a string's contents (escapes kept), a token's text
  std::vector<Node> items;

  bool is_token(std::string_view t) const { return kind == Kind::kToken && text == t; }
  bool is_list() const { return kind == Kind::kList; }
};

/// Reads the text's top-level forms (with the one scanner of CLIPS source, source_text.h);
/// false on unbalanced parentheses or an open string.
bool parse(std::string_view text, std::vector<Node>& out) {
  std::vector<std::vector<Node>*> stack = {&out};
  SourceScanner scanner(text);
  SourceToken t;
  while (scanner.next(t)) {
    switch (t.kind) {
      case SourceToken::Kind::kOpen:
        stack.back()->push_back(Node{Node::Kind::kList, {}, {}});
        stack.push_back(&stack.back()->back().items);
        break;
      case SourceToken::Kind::kClose:
        if (stack.size() == 1) return false;
        stack.pop_back();
        break;
      case SourceToken::Kind::kString:
        if (!t.closed) return false;
        stack.back()->push_back(Node{
            Node::Kind::kString, std::string(text.substr(t.begin + 1, t.end - t.begin - 2)), {}});
        break;
      case SourceToken::Kind::kAtom:
        stack.back()->push_back(
            Node{Node::Kind::kToken, std::string(text.substr(t.begin, t.end - t.begin)), {}});
        break;
    }
  }
  return stack.size() == 1;
}

/// Is `n` a call of a function that reaches facts or code by text?
bool dynamic_call(const Node& n) {
  if (!n.is_list() || n.items.empty() || n.items[0].kind != Node::Kind::kToken) return false;
  for (const std::string_view f : kDynamic) {
    if (n.items[0].text == f) return true;
  }
  return false;
}

/// Does `n` name the template or call a function that reaches facts or code by text?
bool reaches_messages(const Node& n) {
  switch (n.kind) {
    case Node::Kind::kToken:
      return n.text == kTemplate;
    case Node::Kind::kString:
      return n.text.find(kTemplate) != std::string::npos;
    case Node::Kind::kList:
      if (dynamic_call(n)) return true;
      for (const Node& k : n.items) {
        if (reaches_messages(k)) return true;
      }
      return false;
  }
  return true;
}

/// A rule's condition element: false if it could match a message of any type; the types its
/// protobuf-msg patterns name go to `types`.
bool condition(const Node& n, TypeNames& types) {
  if (!n.is_list()) return !reaches_messages(n);
  if (n.items.empty() || !n.items[0].is_token(kTemplate)) {
    if (dynamic_call(n)) return false;
    for (const Node& k : n.items) {
      if (!condition(k, types)) return false;
    }
    return true;
  }
  // A protobuf-msg pattern: exactly one (type "NAME") slot, and nothing dynamic in the others.
  const Node* type = nullptr;
  for (std::size_t i = 1; i < n.items.size(); ++i) {
    const Node& slot = n.items[i];
    if (slot.is_list() && !slot.items.empty() && slot.items[0].is_token("type")) {
      if (type != nullptr || slot.items.size() != 2 || slot.items[1].kind != Node::Kind::kString) {
        return false;
      }
      type = &slot.items[1];
    } else if (reaches_messages(slot)) {
      return false;
    }
  }
  if (type == nullptr || type->text.find('\\') != std::string::npos) return false;
  types.insert(type->text);
  return true;
}

}  // namespace

std::optional<TypeNames> matched_message_types(std::span<const std::string> construct_texts) {
  TypeNames types;
  std::vector<Node> forms;
  for (const std::string& text : construct_texts) {
    forms.clear();
    if (!parse(text, forms)) return std::nullopt;
    for (const Node& form : forms) {
      if (!form.is_list() || form.items.empty() || !form.items[0].is_token("defrule")) {
        if (reaches_messages(form)) return std::nullopt;
        continue;
      }
      // (defrule NAME ["comment"] CE... => ACTION...)
      bool actions = false;
      for (std::size_t i = 2; i < form.items.size(); ++i) {
        const Node& e = form.items[i];
        if (!actions && e.is_token("=>")) {
          actions = true;
        } else if (actions ? reaches_messages(e) : !condition(e, types)) {
          return std::nullopt;
        }
      }
    }
  }
  return types;
}

}  // namespace llsf::clips::detail
