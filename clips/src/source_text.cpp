// SPDX-License-Identifier: MIT
// The reader of CLIPS source text (source_text.h): its scanner, and the tree read from the
// scanner's tokens, iteratively and bounded in depth.
#include "source_text.h"

#include <cctype>

namespace llsf::clips::detail {

std::string_view SourceNode::head() const {
  if (kind != Kind::kList || items.empty() || items.front().kind != Kind::kAtom) return {};
  return items.front().text;
}

bool SourceScanner::next(SourceToken& out) {
  const std::size_t n = text_.size();
  while (i_ < n) {
    const char c = text_[i_];
    if (c == '\n') {
      ++line_;
      ++i_;
    } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      ++i_;
    } else if (c == ';') {
      while (i_ < n && text_[i_] != '\n') ++i_;
    } else {
      out.begin = i_;
      out.line = line_;
      out.closed = true;
      if (c == '(' || c == ')') {
        out.kind = c == '(' ? SourceToken::Kind::kOpen : SourceToken::Kind::kClose;
        ++i_;
      } else if (c == '"') {
        out.kind = SourceToken::Kind::kString;
        for (++i_; i_ < n && text_[i_] != '"'; ++i_) {
          if (text_[i_] == '\\' && i_ + 1 < n) ++i_;
          if (text_[i_] == '\n') ++line_;
        }
        out.closed = i_ < n;
        if (out.closed) ++i_;  // the closing quote
      } else {
        out.kind = SourceToken::Kind::kAtom;
        while (i_ < n && std::isspace(static_cast<unsigned char>(text_[i_])) == 0 &&
               text_[i_] != '(' && text_[i_] != ')' && text_[i_] != '"' && text_[i_] != ';')
          ++i_;
      }
      out.end = i_;
      return true;
    }
  }
  return false;
}

std::string string_contents(std::string_view text, const SourceToken& token) {
  std::string s;
  const std::size_t n = token.end;
  for (std::size_t i = token.begin + 1; i < n && text[i] != '"'; ++i) {
    if (text[i] == '\\' && i + 1 < n) ++i;
    s += text[i];
  }
  return s;
}

std::vector<SourceNode> read_source(std::string_view text) {
  SourceNode root;
  root.kind = SourceNode::Kind::kList;
  std::vector<SourceNode*> open = {&root};  // the lists being read, innermost last
  int skipped = 0;                          // depth inside a list deeper than kMaxSourceDepth
  SourceScanner scanner(text);
  SourceToken t;
  while (scanner.next(t)) {
    switch (t.kind) {
      case SourceToken::Kind::kOpen: {
        if (skipped > 0 || static_cast<int>(open.size()) > kMaxSourceDepth) {
          ++skipped;
          break;
        }
        SourceNode l;
        l.kind = SourceNode::Kind::kList;
        l.line = t.line;
        open.back()->items.push_back(std::move(l));
        open.push_back(&open.back()->items.back());
        break;
      }
      case SourceToken::Kind::kClose:
        if (skipped > 0) {
          --skipped;
        } else if (open.size() > 1) {
          open.pop_back();
        }
        break;
      case SourceToken::Kind::kString:
      case SourceToken::Kind::kAtom:
        if (skipped == 0) {
          SourceNode a;
          a.kind = t.kind == SourceToken::Kind::kString ? SourceNode::Kind::kString
                                                        : SourceNode::Kind::kAtom;
          a.text = a.kind == SourceNode::Kind::kString
                       ? string_contents(text, t)
                       : std::string(text.substr(t.begin, t.end - t.begin));
          a.line = t.line;
          open.back()->items.push_back(std::move(a));
        }
        break;
    }
  }
  return std::move(root.items);
}

namespace {

std::string_view without_module(std::string_view name) {
  const std::size_t p = name.rfind("::");
  return p == std::string_view::npos ? name : name.substr(p + 2);
}

}  // namespace

std::vector<const SourceNode*> rule_lhs(const SourceNode& rule) {
  std::vector<const SourceNode*> out;
  for (std::size_t k = 2; k < rule.items.size(); ++k) {
    const SourceNode& f = rule.items[k];
    if (f.kind == SourceNode::Kind::kAtom && f.text == "=>") break;
    if (f.kind == SourceNode::Kind::kString && out.empty()) continue;  // the comment
    if (f.head() == "declare") continue;
    out.push_back(&f);
  }
  return out;
}

namespace {

bool is_group(std::string_view head) {
  return head == "and" || head == "or" || head == "not" || head == "exists" || head == "forall" ||
         head == "logical";
}

void collect_conditions(const SourceNode& ce, std::vector<const SourceNode*>& out) {
  if (!ce.is_list()) return;  // `?f`, `<-`: the pattern after them counts
  if (is_group(ce.head())) {
    for (std::size_t k = 1; k < ce.items.size(); ++k) collect_conditions(ce.items[k], out);
    return;
  }
  out.push_back(&ce);
}

}  // namespace

const SourceNode* find_defrule(const std::vector<SourceNode>& forms, std::string_view name) {
  const std::string_view want = without_module(name);
  for (const SourceNode& f : forms) {
    if (f.head() != "defrule" || f.items.size() < 2) continue;
    if (without_module(f.items[1].text) == want) return &f;
  }
  return nullptr;
}

std::vector<const SourceNode*> rule_conditions(const SourceNode& rule) {
  std::vector<const SourceNode*> out;
  for (const SourceNode* f : rule_lhs(rule)) collect_conditions(*f, out);
  return out;
}

std::string_view bound_relation(const SourceNode& rule, std::string_view variable) {
  const std::vector<const SourceNode*> forms = rule_lhs(rule);
  for (std::size_t k = 0; k + 2 < forms.size(); ++k) {
    if (forms[k]->kind == SourceNode::Kind::kAtom && forms[k]->text == variable &&
        forms[k + 1]->kind == SourceNode::Kind::kAtom && forms[k + 1]->text == "<-")
      return forms[k + 2]->head();
  }
  return {};
}

}  // namespace llsf::clips::detail
