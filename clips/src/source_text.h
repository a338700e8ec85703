// SPDX-License-Identifier: MIT
// A small reader of CLIPS source text: its tokens (parentheses, atoms, strings) with their places
// (`SourceScanner`, which the agent host's batch files are split with), and the tree of lists,
// atoms and strings read from them (`read_source`): enough to find a rule's conditional elements
// (the line of CE #n in a CLIPS error) and to look at rule conditions for `check`'s warnings. It
// parses no more than it must and never fails.
#pragma once

#include <cstddef>

#include <string>
#include <string_view>
#include <vector>

namespace llsf::clips::detail {

/// One token of the source: `(`, `)`, an atom (anything up to white space, a parenthesis, `"` or
/// `;`) or a string (from `"` to the next `"` not escaped by a backslash).
struct SourceToken {
  enum class Kind { kOpen, kClose, kAtom, kString };
  Kind kind = Kind::kAtom;
  /// The offset of its first character (a string's: its opening quote).
  std::size_t begin = 0;
  /// The offset after its last character (a string's: its closing quote, else the text's end).
  std::size_t end = 0;
  int line = 1;        ///< the 1-based line where it starts
  bool closed = true;  ///< false for a string that the text ends in (no closing quote)
};

/// The tokens of a text in order, white space and comments (`;` to the end of the line) skipped;
/// lines count every newline, also those inside strings. Borrows the text.
class SourceScanner {
 public:
  explicit SourceScanner(std::string_view text) : text_(text) {}
  /// Reads the next token into `out`; false at the end of the text.
  bool next(SourceToken& out);

 private:
  std::string_view text_;
  std::size_t i_ = 0;
  int line_ = 1;
};

/// A string token's contents without its quotes, each escaped character (`\"`) as it follows
/// its backslash.
std::string string_contents(std::string_view text, const SourceToken& token);

/// One form of the source: a list `( ... )`, an atom (symbol, number, variable, `=>`, `<-`,
/// `?x&:`) or a string.
struct SourceNode {
  enum class Kind { kList, kAtom, kString };
  Kind kind = Kind::kAtom;
  std::string text;               ///< the atom's or string's text (a string without its quotes)
  int line = 1;                   ///< the 1-based line where the form starts
  std::vector<SourceNode> items;  ///< a list's forms
  /// The first item of a list if it is an atom ("defrule", "test", a relation name), else "".
  std::string_view head() const;
  bool is_list() const { return kind == Kind::kList; }
};

/// Lists nested deeper than this are read as empty lists (their text is skipped): the readers
/// of the tree recurse, and hostile input may nest without end.
inline constexpr int kMaxSourceDepth = 200;

/// The top-level forms of `text`, comments (`;` to the end of the line) left out. Lenient: an
/// unclosed list ends at the end of the text, a stray `)` is skipped.
std::vector<SourceNode> read_source(std::string_view text);

/// The defrule named `name` (a module prefix "MAIN::" is ignored), nullptr if there is none.
const SourceNode* find_defrule(const std::vector<SourceNode>& forms, std::string_view name);

/// The forms of a defrule's left-hand side, in order: after its name, comment and (declare ...),
/// up to `=>` (conditional elements, and the `?f` and `<-` atoms of a fact binding).
std::vector<const SourceNode*> rule_lhs(const SourceNode& rule);

/// The conditional elements of a defrule's left-hand side as CLIPS numbers them in its messages
/// ("CE #2"): patterns and test CEs in text order, also those inside and, or, not, exists,
/// forall and logical; each the list of the pattern or test.
std::vector<const SourceNode*> rule_conditions(const SourceNode& rule);

/// The variable bound to a fact by `?f <- (pattern)` in a rule's left-hand side, the pattern's
/// relation name ("" if `?f` binds none).
std::string_view bound_relation(const SourceNode& rule, std::string_view variable);

}  // namespace llsf::clips::detail
