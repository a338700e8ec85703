// SPDX-License-Identifier: MIT
// TimeReadCheck (source_check.h): rule conditions that read the clock where CLIPS does not
// evaluate them again as time passes.
#include "llsf/clips/source_check.h"

#include <algorithm>
#include <cctype>

#include "source_text.h"

namespace llsf::clips {

namespace {

using detail::SourceNode;
using Names = std::set<std::string, std::less<>>;

// The first function of `fns` called inside `n` ("now"), or "".
std::string_view time_call(const SourceNode& n, const Names& fns) {
  if (!n.is_list()) return {};
  if (const std::string_view h = n.head(); !h.empty() && fns.find(h) != fns.end()) return h;
  for (const SourceNode& c : n.items) {
    if (const std::string_view f = time_call(c, fns); !f.empty()) return f;
  }
  return {};
}

// The variables named in `n` (`?x`, `$?x`, `?x&:` -> x).
void variables(const SourceNode& n, std::set<std::string>& out) {
  if (n.is_list()) {
    for (const SourceNode& c : n.items) variables(c, out);
    return;
  }
  if (n.kind != SourceNode::Kind::kAtom) return;
  const std::string& t = n.text;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] != '?') continue;
    std::size_t e = i + 1;
    while (e < t.size() && (std::isalnum(static_cast<unsigned char>(t[e])) != 0 || t[e] == '_' ||
                            t[e] == '-' || t[e] == '*'))
      ++e;
    if (e > i + 1) out.insert(t.substr(i + 1, e - i - 1));
    i = e - 1;
  }
}

bool shares(const std::set<std::string>& a, const std::set<std::string>& b) {
  return std::any_of(a.begin(), a.end(), [&b](const std::string& v) { return b.count(v) > 0; });
}

// What the conditions before a point hold: a positive (time ...) pattern, the variables bound.
struct Context {
  bool time_seen = false;
  std::set<std::string> bound;
};

// One rule's conditional elements, in order.
class RuleScan {
 public:
  RuleScan(const Names& fns, std::string_view rule, std::vector<SourceWarning>& out)
      : fns_(fns), rule_(rule), out_(out) {}

  // The forms `forms` of one level (the left-hand side, or a group's members).
  void walk(const std::vector<const SourceNode*>& forms, Context& ctx, bool negated) {
    for (std::size_t k = 0; k < forms.size(); ++k) {
      const SourceNode& f = *forms[k];
      if (!f.is_list()) {  // `?f <- (pattern)`: the pattern binds ?f
        if (k + 2 < forms.size() && forms[k + 1]->text == "<-" && forms[k + 2]->is_list()) {
          pattern(*forms[k + 2], ctx, negated);
          if (!negated) variables(f, ctx.bound);
          k += 2;
        }
        continue;
      }
      const std::string_view head = f.head();
      std::vector<const SourceNode*> members;
      for (std::size_t m = 1; m < f.items.size(); ++m) members.push_back(&f.items[m]);
      if (head == "and" || head == "logical") {
        walk(members, ctx, negated);
      } else if (head == "or") {
        for (const SourceNode* m : members) {
          Context branch = ctx;
          walk({m}, branch, negated);
        }
      } else if (head == "not" || head == "exists" || head == "forall") {
        Context inner = ctx;  // what is matched inside binds nothing outside
        walk(members, inner, true);
      } else if (head == "test") {
        test(f, ctx);
      } else {
        pattern(f, ctx, negated);
      }
    }
  }

 private:
  void test(const SourceNode& t, const Context& ctx) {
    const std::string_view fn = time_call(t, fns_);
    if (fn.empty() || ctx.time_seen) return;
    out_.push_back(
        {t.line, "rule " + rule_ + ": (test ...) reads the time (" + reads(fn) +
                     ") but no (time ...) pattern comes before it: CLIPS evaluates a test again "
                     "only when the facts matched before it change, so this one does not see "
                     "time pass and the rule fires late or never; put (time ? ?) before the "
                     "test (docs/clips.md, \"Where the (time) pattern goes\")"});
  }

  void pattern(const SourceNode& p, Context& ctx, bool negated) {
    const std::string relation(p.head());
    if (relation == "time") {  // its constraints are tested against every new time fact
      if (!negated) ctx.time_seen = true;
    } else {
      for (std::size_t i = 1; i < p.items.size(); ++i) {
        const SourceNode& slot = p.items[i];
        const std::string_view fn = time_call(slot, fns_);
        if (fn.empty()) continue;
        std::set<std::string> used;
        variables(slot, used);
        // A constraint that joins a variable of an earlier pattern is tested again with every
        // new time fact matched before it; one on its own fact's values only when that changes.
        if (ctx.time_seen && shares(used, ctx.bound)) continue;
        out_.push_back(
            {p.line, "rule " + rule_ + ": the pattern (" + relation + " ...) reads the time (" +
                         reads(fn) +
                         ") in a slot constraint: CLIPS tests a pattern's constraints when its "
                         "fact changes, not as time passes, so the rule fires late or never; "
                         "bind the slot to a variable and compare after a (time) pattern, e.g. "
                         "(time ? ?) (test (> (now) ?until)) (docs/clips.md, \"Where the "
                         "(time) pattern goes\")"});
        break;
      }
    }
    if (!negated) variables(p, ctx.bound);
  }

  static std::string reads(std::string_view fn) {
    if (fn == "now" || fn == "now-sec-usec") return "(" + std::string(fn) + ")";
    return "(" + std::string(fn) + " ...), which calls (now)";
  }

  const Names& fns_;
  std::string rule_;
  std::vector<SourceWarning>& out_;
};

}  // namespace

std::vector<SourceWarning> TimeReadCheck::scan(std::string_view code) {
  std::vector<SourceWarning> out;
  for (const SourceNode& form : detail::read_source(code)) {
    const std::string_view kind = form.head();
    if (form.items.size() < 2 || form.items[1].kind != SourceNode::Kind::kAtom) continue;
    const std::string& name = form.items[1].text;
    if (kind == "deffunction" || kind == "defmethod") {
      for (std::size_t i = 2; i < form.items.size(); ++i) {
        if (!time_call(form.items[i], time_functions_).empty()) {
          time_functions_.insert(name);
          break;
        }
      }
    } else if (kind == "defrule") {
      Context ctx;
      RuleScan(time_functions_, name, out).walk(detail::rule_lhs(form), ctx, false);
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const SourceWarning& a, const SourceWarning& b) { return a.line < b.line; });
  return out;
}

}  // namespace llsf::clips
