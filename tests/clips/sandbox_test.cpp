// SPDX-License-Identifier: MIT
// The agents' sandbox (docs/security.md): no files, I/O, process control or construct removal.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/clips/agent.h"
#include "llsf/clips/testing.h"

using namespace llsf;
using namespace llsf::clips;

namespace {

// A scratch file that must survive every attempt of the agent.
struct ScratchFile {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("llsf-sandbox-" + std::to_string(::getpid()) + ".txt");
  ScratchFile() { std::ofstream(path) << "precious\n"; }
  ~ScratchFile() { std::filesystem::remove(path); }
  bool intact() const {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line == "precious";
  }
};

std::string load_error(AgentFixture& f, const std::string& code) {
  try {
    f.load(code, "agent.clp");
  } catch (const AgentLoadError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST_CASE("sandbox: calls of file, I/O and process functions are load errors with their line") {
  ScratchFile file;
  const std::string reason =
      ": not available in agents (the sandbox: no files, I/O, process control or removal of "
      "constructs; docs/security.md)";
  // One construct per function the sandbox takes away; each must fail where it is called.
  const char* const calls[] = {"(open \"F\" f \"r\")",
                               "(close f)",
                               "(read)",
                               "(readline)",
                               "(remove \"F\")",
                               "(rename \"F\" \"G\")",
                               "(load \"F\")",
                               "(load* \"F\")",
                               "(bload \"F\")",
                               "(batch \"F\")",
                               "(batch* \"F\")",
                               "(save \"F\")",
                               "(bsave \"F\")",
                               "(save-facts \"F\")",
                               "(load-facts \"F\")",
                               "(dribble-on \"F\")",
                               "(dribble-off)",
                               "(exit)",
                               "(clear)",
                               "(reset)",
                               "(undeftemplate time)",
                               "(undefrule x)",
                               "(undeffacts x)",
                               "(undefglobal x)",
                               "(undeffunction x)",
                               "(get-char)",
                               "(read-number)"};
  for (const char* call : calls) {
    CAPTURE(call);
    AgentFixture f;
    std::string code = std::string("; line 1\n(defrule r (go) =>\n  ") + call + ")\n";
    const std::string name = std::string(call).substr(1, std::string(call).find_first_of(" )") - 1);
    const std::string err = load_error(f, code);
    CHECK(err.find("agent.clp:3: [LLSF2] " + name + reason) != std::string::npos);
  }
  // A defglobal's initializer runs while the file loads (and in `llsfsim check`): refused too.
  AgentFixture g;
  const std::string err =
      load_error(g, "(defglobal ?*x* = (remove \"" + file.path.string() + "\"))\n");
  CHECK(err.find("agent.clp:1: [LLSF2] remove" + reason) != std::string::npos);
  CHECK(file.intact());
}

TEST_CASE("sandbox: eval, build and funcall at run time fail as runtime errors naming the rule") {
  ScratchFile file;
  AgentFixture f;
  f.load("(defrule by-eval (a) => (eval \"(open \\\"" + file.path.string() +
             "\\\" f \\\"w\\\")\"))\n"
             "(defrule by-funcall (b) => (funcall remove \"" +
             file.path.string() +
             "\"))\n"
             "(defrule by-build (c) => (build \"(defrule x => (exit))\"))\n"
             "(defrule by-string (d) => (funcall (sym-cat \"ex\" \"it\")))\n"
             "(defrule alive (time $?) => (assert (alive)))\n",
         "agent.clp");
  f.step();
  const auto trigger = [&](const char* fact) {
    f.assert_fact(fact);
    return f.step().runtime_errors;
  };
  CHECK(trigger("(a)") == 1);
  CHECK(
      f.logged("runtime error in rule by-eval (agent.clp:1): [LLSF2] open: not available in "
               "agents"));
  // funcall refuses every function with its own parser, which the sandbox gives them (CLIPS
  // does not halt the rule for it; the host names the rule that was running).
  CHECK(trigger("(b)") == 1);
  CHECK(
      f.logged("runtime error in rule by-funcall (agent.clp:2): [ARGACCES5] Function funcall "
               "expected argument #1 to be of type function without specialized parser"));
  // build only returns FALSE on a parse error (CLIPS halts nothing); the message is reported
  // with the next cycle's errors, if any: the rule x was not built.
  trigger("(c)");
  CHECK(f.agent().eval("(member$ x (get-defrule-list))") == Value::symbol("FALSE"));
  CHECK(trigger("(d)") == 1);
  CHECK(f.logged("[LLSF2] exit: not available in agents"));
  CHECK(file.intact());
  // The process is still here and the agent goes on.
  f.step();
  CHECK(f.has("(alive)"));
}

TEST_CASE("sandbox off (a trusted local agent): files work") {
  ScratchFile file;
  AgentConfig cfg;
  cfg.sandbox = false;
  AgentFixture f(cfg);
  const std::filesystem::path out = file.path.string() + ".out";
  f.load(
      "(defrule write (time $?) (not (done)) => (assert (done))\n"
      "  (open \"" +
          out.string() + "\" o \"w\") (printout o \"hello\" crlf) (close o))\n",
      "trusted.clp");
  f.step();
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  CHECK(line == "hello");
  std::filesystem::remove(out);
}
