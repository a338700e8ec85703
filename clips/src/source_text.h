// SPDX-License-Identifier: MIT
// A small reader of CLIPS source text into lists, atoms and strings with their lines: enough to
// find a rule's conditional elements (the line of CE #n in a CLIPS error) and to look at rule
// conditions for `check`'s warnings. It parses no more than it must and never fails.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace llsf::clips::detail {

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
