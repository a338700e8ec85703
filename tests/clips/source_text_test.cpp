// SPDX-License-Identifier: MIT
// The one scanner of CLIPS source (clips/src/source_text.h): tokens with their offsets and lines,
// comments skipped, strings with escapes and newlines; and the tree read_source builds from it.
#include <doctest/doctest.h>

#include <string>
#include <string_view>
#include <vector>

#include "source_text.h"

using namespace llsf::clips::detail;

namespace {

struct Token {
  SourceToken::Kind kind;
  std::string text;  // the token's text as it stands in the source
  int line;
  bool operator==(const Token&) const = default;
};

std::vector<Token> tokens(std::string_view text) {
  std::vector<Token> out;
  SourceScanner scanner(text);
  SourceToken t;
  while (scanner.next(t)) {
    out.push_back({t.kind, std::string(text.substr(t.begin, t.end - t.begin)), t.line});
  }
  return out;
}

constexpr SourceToken::Kind kOpen = SourceToken::Kind::kOpen;
constexpr SourceToken::Kind kClose = SourceToken::Kind::kClose;
constexpr SourceToken::Kind kAtom = SourceToken::Kind::kAtom;
constexpr SourceToken::Kind kString = SourceToken::Kind::kString;

}  // namespace

TEST_CASE("the scanner: tokens, their text and lines; comments skipped, strings whole") {
  const std::string_view text =
      "; a comment (with a parenthesis\n"  // 1
      "(printout t \"a ; no comment\n"     // 2
      "b \\\"c\\\" \\\n"                   // 3: an escaped quote, an escaped newline
      "\" crlf)?x&:(eq a\"s\")<-;c\n"      // 4
      "(x \"open";                         // 5: a string without its end
  const std::vector<Token> want = {
      {kOpen, "(", 2},       {kAtom, "printout", 2},
      {kAtom, "t", 2},       {kString, "\"a ; no comment\nb \\\"c\\\" \\\n\"", 2},
      {kAtom, "crlf", 4},    {kClose, ")", 4},
      {kAtom, "?x&:", 4},    {kOpen, "(", 4},
      {kAtom, "eq", 4},      {kAtom, "a", 4},
      {kString, "\"s\"", 4}, {kClose, ")", 4},
      {kAtom, "<-", 4},      {kOpen, "(", 5},
      {kAtom, "x", 5},       {kString, "\"open", 5},
  };
  CHECK(tokens(text) == want);
  SourceScanner scanner(text);
  SourceToken t;
  for (int k = 0; k < 4; ++k) REQUIRE(scanner.next(t));
  CHECK(string_contents(text, t) == "a ; no comment\nb \"c\" \n");
  CHECK(t.closed);
  while (scanner.next(t)) {
  }
  CHECK_FALSE(t.closed);  // the last string: the text ends in it
  CHECK(tokens("  \n ; only a comment") == std::vector<Token>{});
}

TEST_CASE("read_source: the tree of the scanner's tokens, lenient and bounded in depth") {
  const std::vector<SourceNode> forms =
      read_source("(defrule r \"doc\"\n  (a \"x\\\"y\")\n =>)\n) atom (unclosed (list");
  REQUIRE(forms.size() == 3);  // the stray ')' skipped
  CHECK(forms[0].head() == "defrule");
  REQUIRE(forms[0].items.size() == 5);
  CHECK(forms[0].items[2].kind == SourceNode::Kind::kString);
  CHECK(forms[0].items[2].text == "doc");
  CHECK(forms[0].items[3].line == 2);
  CHECK(forms[0].items[3].items[1].text == "x\"y");
  CHECK(forms[0].items[4].text == "=>");
  CHECK(forms[0].items[4].line == 3);
  CHECK(forms[1].text == "atom");
  CHECK(forms[1].line == 4);
  CHECK(forms[2].head() == "unclosed");
  CHECK(forms[2].items.at(1).head() == "list");

  std::string deep(static_cast<std::size_t>(kMaxSourceDepth) + 5, '(');
  deep += "x" + std::string(static_cast<std::size_t>(kMaxSourceDepth) + 5, ')') + " after";
  const std::vector<SourceNode> d = read_source(deep);
  REQUIRE(d.size() == 2);
  CHECK(d[1].text == "after");
  const SourceNode* n = &d[0];
  int depth = 1;
  while (!n->items.empty()) {
    n = &n->items[0];
    ++depth;
  }
  CHECK(depth == kMaxSourceDepth);
  CHECK(n->is_list());  // the deepest list read, empty: what is deeper is skipped
}
