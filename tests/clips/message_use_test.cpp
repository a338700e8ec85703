// SPDX-License-Identifier: MIT
// Which message types an agent's rules can match (message_use.h); that a message of another type
// makes no protobuf-msg fact is tested with the protobuf feature (protobuf_test.cpp).
#include "message_use.h"

#include <doctest/doctest.h>

#include <string>
#include <vector>

using llsf::clips::detail::matched_message_types;
using llsf::clips::detail::TypeNames;

namespace {

std::optional<TypeNames> types_of(std::vector<std::string> texts) {
  return matched_message_types(texts);
}

}  // namespace

TEST_CASE("message use: the types named by the rules' protobuf-msg patterns") {
  const std::string a =
      "(defrule MAIN::a (declare (salience 10)) ?pf <- (protobuf-msg (type \"x.A\") (ptr ?p) "
      "(rcvd-from ?f $?)) => (retract ?pf) (printout t (pb-field-value ?p \"n\") crlf))";
  const auto t = types_of({
      a,
      "(defrule MAIN::b \"a comment\" (game) (not (protobuf-msg (type \"x.B\"))) => (assert (c)))",
      "(defrule MAIN::c (exists (protobuf-msg (type \"x.A\"))) (test (> 2 1)) =>)",
      "(deffunction MAIN::f (?x) (+ ?x 1))",
      "(defglobal MAIN ?*G* = 0)",
  });
  REQUIRE(t.has_value());
  CHECK(*t == TypeNames{"x.A", "x.B"});
  CHECK(types_of({})->empty());  // no rule wants any message
}

TEST_CASE("message use: any other mention of protobuf-msg means every type") {
  const std::vector<std::string> any = {
      "(defrule MAIN::r (protobuf-msg (ptr ?p)) =>)",                    // no type
      "(defrule MAIN::r (protobuf-msg (type ?t)) =>)",                   // a variable
      "(defrule MAIN::r (protobuf-msg (type \"x.A\"|\"x.B\")) =>)",      // alternatives
      "(defrule MAIN::r (protobuf-msg (type ?t&:(eq ?t \"x.A\"))) =>)",  // a test
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") (type \"x.B\")) =>)",
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") (ptr ?p&:(eval \"TRUE\"))) =>)",
      "(defrule MAIN::r (go) => (do-for-all-facts ((?m protobuf-msg)) TRUE (retract ?m)))",
      "(defrule MAIN::r (go) (test (any-factp ((?m protobuf-msg)) TRUE)) =>)",
      "(deffunction MAIN::f () (find-all-facts ((?m protobuf-msg)) TRUE))",
      "(defrule MAIN::r (go) => (build \"(defrule s (go) =>)\"))",
      "(defrule MAIN::r (go) => (eval \"(facts)\"))",
      "(defrule MAIN::r (go) => (facts))",
      "(defrule MAIN::r (go) => (bind ?l (get-fact-list)))",
      "(defrule MAIN::r (go) => (printout t \"protobuf-msg\" crlf))",
      "(defrule MAIN::r (protobuf-msg (type \"x.A\") =>",  // unbalanced: not understood
  };
  for (const std::string& text : any) {
    INFO(text);
    CHECK_FALSE(types_of({"(defrule MAIN::ok (protobuf-msg (type \"x.A\")) =>)", text}));
  }
}
