// SPDX-License-Identifier: MIT
// Environment: a thin C++ wrapper around one CLIPS 6.30 environment. It is the only code that
// sees the CLIPS headers (environment.cpp): they are C-only, define ~230 function-like macros
// (GetType, SetValue, ...) and a global `struct field`. Features talk to CLIPS through this.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/clips/value.h"

namespace llsf::clips::detail {

class Environment;

/// One argument read once without copying its text (Args::view; valid during the call only).
struct ArgView {
  Value::Type type = Value::Type::kVoid;
  std::int64_t integer = 0;  ///< kInteger
  double real = 0.0;         ///< kFloat
  std::string_view text;     ///< kSymbol, kString (null-terminated: CLIPS' symbol table)
  void* address = nullptr;   ///< kAddress
  Value whole;               ///< kMultifield and kFact only: the copied value
  bool is_number() const { return type == Value::Type::kInteger || type == Value::Type::kFloat; }
  double number() const {
    return type == Value::Type::kInteger ? static_cast<double>(integer)
                                         : (type == Value::Type::kFloat ? real : 0.0);
  }
  bool is_symbol(std::string_view s) const { return type == Value::Type::kSymbol && text == s; }
  /// The argument as a Value (for messages).
  Value to_value() const;
};

/// The arguments of a call of a user-defined function (valid during the call only). Indices are
/// 0-based. The typed accessors read without copying into a Value (cheap in LHS tests). A
/// function may also set its result directly (return_*; then what it returns is ignored), which
/// spares the Value in between.
class Args {
 public:
  Args(Environment& env, void* clips_env, std::string_view function, void* result = nullptr)
      : env_(env), clips_env_(clips_env), function_(function), result_(result) {}
  int count() const;
  Value::Type type(int i) const;
  /// The argument as a Value (copies text and multifields).
  Value value(int i) const;
  /// INTEGER or FLOAT.
  bool number(int i, double& out) const;
  /// INTEGER (or a FLOAT with an integral value).
  bool integer(int i, std::int64_t& out) const;
  /// SYMBOL or STRING; the view points into CLIPS' symbol table (valid during the call).
  bool text(int i, std::string_view& out) const;
  /// EXTERNAL-ADDRESS.
  bool address(int i, void*& out) const;
  /// A time: a multifield (sec usec) as in (time sec usec) facts, or a number of seconds.
  bool time(int i, double& seconds) const;
  /// The argument, evaluated once (an argument's expression runs on every read: read it once).
  ArgView view(int i) const;
  /// The function's name (for error messages).
  std::string_view function() const { return function_; }
  Environment& env() const { return env_; }

  /// Sets the call's result directly (only inside a dispatched call): the text must be
  /// null-terminated.
  void return_symbol(const char* text);
  void return_string(const char* text);
  void return_integer(std::int64_t i);
  void return_float(double d);
  void return_external(void* p);
  void return_boolean(bool b);
  /// True once a return_* was called.
  bool returned() const { return returned_; }

 private:
  Environment& env_;
  void* clips_env_;
  std::string_view function_;
  void* result_;  // the call's DATA_OBJECT*
  bool returned_ = false;
};

/// A fact kept alive for later retraction (CLIPS' fact count is incremented while held).
class FactHandle {
 public:
  bool empty() const { return fact_ == nullptr; }

 private:
  friend class Environment;
  void* fact_ = nullptr;
};

/// A deftemplate looked up once; assert_fact() takes values in `slots` order.
struct Template {
  void* ptr = nullptr;
  std::string name;
  std::vector<std::string> slots;  ///< empty for ordered (implied) facts
  bool implied = false;
  /// Index of `slot` in `slots`; throws std::logic_error if absent.
  int slot_index(std::string_view slot) const;
};

/// A fact copied out of the environment (for queries).
struct FactCopy {
  std::int64_t index = 0;
  std::string template_name;
  /// Slot name and value; an ordered fact has one entry with an empty name holding a multifield.
  std::vector<std::pair<std::string, Value>> slots;
};

/// One syntax/semantic error found while loading constructs.
struct LoadError {
  int line = 0;         ///< 1-based line of the source text where CLIPS noticed the error
  std::string message;  ///< e.g. "[PRNTUTIL2] Syntax Error: ... (in defrule MAIN::foo)"
};

/// Receives an environment's rule firings and fact changes (AgentHost's trace). Called from
/// inside CLIPS: implementations must not throw.
class TraceObserver {
 public:
  virtual ~TraceObserver() = default;
  /// A rule is about to fire; `facts` are the indices of the facts that matched its patterns in
  /// order (not and exists patterns match no fact and are left out).
  virtual void on_fire(std::string_view rule, std::span<const std::int64_t> facts) = 0;
  /// A fact was asserted (`asserted`) or is about to be retracted; `text` as CLIPS prints it,
  /// "(machine (name M1) (mtype T1))".
  virtual void on_fact(bool asserted, std::int64_t index, std::string_view text) = 0;
};

/// One CLIPS environment. Not copyable or movable (CLIPS keeps pointers to it). Not thread-safe.
class Environment {
 public:
  /// Called with complete output text per logical name ("t", "werror", "warn", ...).
  using OutputHandler = std::function<void(std::string_view logical_name, std::string_view text)>;
  /// A user-defined function; return Value{} for no result. Report bad arguments with error().
  using Function = std::function<Value(Args&)>;

  Environment();
  ~Environment();
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;

  /// Output of printout and of CLIPS' own messages (except werror while loading, see load()).
  void set_output_handler(OutputHandler handler) { output_ = std::move(handler); }

  /// Defines (or replaces, e.g. `random`) a function. `restrictions` is CLIPS' argument
  /// restriction string ("22n": exactly two numbers, "1**": at least one of any type).
  void define_function(const std::string& name, const std::string& restrictions, Function fn);
  /// Makes a function unavailable (the agents' sandbox): a call of `name` in code loaded later,
  /// or parsed by eval/build, is an error "[LLSF2] name: message" (a load error with its line);
  /// a call that needs no parsing (funcall) fails the same way at run time. A function this
  /// CLIPS does not have is skipped.
  void forbid_function(const std::string& name, const std::string& message);
  /// Puts the size guard (set_size_limits) on `name`, a function defined before whose result
  /// is the concatenation of its arguments (as str-cat's): its arguments are evaluated once, and
  /// a call whose text would be longer than the string budget fails before `name` runs.
  void guard_concatenation(const std::string& name);
  /// Why `name` is forbidden (forbid_function).
  std::string forbidden_reason(std::string_view name) const;
  /// The names an agent may call: CLIPS' and llsfsim's functions (not the forbidden ones), the
  /// deffunctions and defgenerics (for "did you mean").
  std::vector<std::string> callable_names() const;
  /// The slot names of deftemplate `name` (empty if there is none or it is ordered).
  std::vector<std::string> template_slot_names(const std::string& name) const;
  /// Reports a bad call: prints "[LLSF1] name: message" to werror and sets CLIPS' evaluation
  /// error, which stops the rule's actions (the host then logs it as a runtime error).
  void error(std::string_view function, std::string_view message);

  /// Loads constructs from `text`; returns the errors (empty on success). Lines count from 1.
  std::vector<LoadError> load(const std::string& text);
  /// Counts the calls that may have added constructs: load(), build() and eval() (a rule's
  /// own (build) is not counted).
  std::uint64_t code_version() const { return code_version_; }
  /// Builds one construct (for built-in code that needs no line numbers); throws on error.
  void build(const std::string& construct);

  /// Looks up a deftemplate; throws std::logic_error if it does not exist.
  Template find_template(const std::string& name);
  /// The implied (ordered) deftemplate `name`, created as a fact or pattern `(name ...)` would
  /// create it if no construct has yet; throws std::logic_error if `name` is a deftemplate with
  /// slots.
  Template implied_template(const std::string& name);
  /// Asserts a fact of `t` with `values` in slot order (kVoid keeps the slot's default); for an
  /// ordered template, `values` are the fields. The handle keeps the fact for retract().
  FactHandle assert_fact(const Template& t, std::span<const Value> values);
  /// The same for a deftemplate's fact, the values by pointer (nullptr keeps the slot's default):
  /// nothing copied.
  FactHandle assert_fact(const Template& t, std::span<const Value* const> values);
  /// True if the handle's fact is still in the fact list.
  bool exists(const FactHandle& h) const;
  /// Retracts the fact if it still exists and releases the handle.
  void retract(FactHandle& h);
  /// Retracts every fact of template `t`; returns how many.
  int retract_all(const Template& t);
  /// Releases the handle without retracting.
  void release(FactHandle& h);
  /// Asserts a fact from text (tests and tools; slow path). Returns false on a parse error.
  bool assert_string(const std::string& fact);

  /// Runs at most `limit` rule firings; returns the number fired.
  std::int64_t run(std::int64_t limit);

  /// Why a budget stopped execution.
  enum class BudgetHit : std::uint8_t { kNone, kSteps, kWall, kDepth, kMemory };
  /// The size budgets (0: none). `memory_bytes`: what CLIPS holds for this environment
  /// (EnvMemUsed: facts, symbols, strings, multifields, rules), checked at every budget step
  /// (BudgetHit::kMemory) and before a guarded function builds its result. `string_length` and
  /// `multifield_length`: the largest string (characters) and multifield (fields) that
  /// str-cat, sym-cat, implode$, format, printout, create$, insert$, replace$, explode$,
  /// replace-member$ and their old aliases may build. Those functions are guarded in every
  /// environment: their arguments are evaluated first, the result's size is bounded from them,
  /// and only a call within the budgets reaches CLIPS' own function (with the values); a call
  /// past a budget fails as error() does ("[LLSF1] str-cat: the result would have ...").
  struct SizeLimits {
    std::int64_t memory_bytes = 0;
    std::int64_t string_length = 0;
    std::int64_t multifield_length = 0;
  };
  void set_size_limits(const SizeLimits& limits) { limits_ = limits; }
  const SizeLimits& size_limits() const { return limits_; }
  /// The bytes CLIPS holds for this environment now (EnvMemUsed).
  std::int64_t memory_used() const;
  /// Starts a work budget for the following run()s: a step is one of CLIPS' periodic callbacks
  /// (about two per rule firing, one per iteration of while, loop-for-count, progn$, ...).
  /// Past `max_steps` steps, or (checked every 1,024 steps) past `max_wall_s` seconds of wall
  /// time, execution halts as on an error: the running rule's actions stop. Until the next
  /// start_budget() every further step halts again. A deffunction or generic function call is
  /// also a step; nesting such calls deeper than `max_call_depth` halts too (kDepth), before the
  /// C stack runs out: CLIPS 6.30 makes no periodic callback on the way down a recursion.
  void start_budget(std::int64_t max_steps, double max_wall_s, int max_call_depth);
  BudgetHit budget_hit() const { return budget_hit_; }
  std::int64_t budget_steps() const { return steps_; }
  /// With kDepth: the deffunction or generic function whose call went too deep.
  const std::string& budget_function() const { return budget_function_; }
  /// With kMemory: the bytes CLIPS held when the memory budget stopped execution.
  std::int64_t budget_memory() const { return budget_memory_; }
  /// The rule whose actions are running now, or "" outside of a rule's actions.
  std::string executing_rule() const;
  /// The rule of the first activation on the agenda, or "" if it is empty.
  std::string next_rule() const;
  /// True if the current focus has activations left.
  bool agenda_empty() const;
  /// True after an error stopped execution (CLIPS' halt flag); clear_halt() resets it.
  bool halted() const;
  void clear_halt();
  /// (reset): facts cleared, deffacts asserted, globals reset.
  void reset();

  /// Sets a defglobal (name without ?* *).
  void set_global(const std::string& name, const Value& v);
  /// Evaluates an expression (slow path, tests and tools).
  Value eval(const std::string& expression);
  /// The pretty-print forms of every rule, function, generic function method, deffacts,
  /// defglobal, message-handler and definstances (in no particular order), into `out`; false
  /// if one has none (a construct whose text CLIPS did not keep).
  bool construct_texts(std::vector<std::string>& out) const;
  /// All facts of `template_name` (all facts if empty), in fact-list order.
  std::vector<FactCopy> facts(std::string_view template_name) const;

  /// Installs `observer` (borrowed; nullptr removes it) for rule firings (`rules`) and fact
  /// changes (`facts`). Without an observer no hook is registered with CLIPS: nothing is spent.
  /// `fact_texts` false: on_fact gets an empty text.
  void observe(TraceObserver* observer, bool rules, bool facts, bool fact_texts = true);
  /// The fact with `index` as CLIPS prints it ("(state IDLE)"); "" if there is none.
  std::string fact_text(std::int64_t index) const;
  /// Every fact with an index >= `from_index` as (index, text), in fact-list order (= index
  /// order); `out` is cleared first. Walks from the end: cheap for the newest facts.
  void fact_texts(std::vector<std::pair<std::int64_t, std::string>>& out,
                  std::int64_t from_index = 0) const;

 private:
  struct FunctionEntry {
    Environment* self;
    std::string name;
    std::string restrictions;
    Function fn;
  };
  friend struct RouterAccess;
  friend struct TraceHooks;
  void on_print(std::string_view logical_name, std::string_view text);
  template <class Values>
  FactHandle assert_slots(const Template& t, Values values);
  // Asserts a fact made by EnvCreateFact and holds it (a handle to nothing if CLIPS refused it).
  FactHandle assert_created(void* fact);
  static void periodic(void* clips_env);
  void print_fact(void* fact, std::string& out) const;
  // The call guard: CLIPS' evaluators of deffunction (PCALL) and generic function (GCALL) calls,
  // replaced in this environment by ones that count depth and steps (environment.cpp).
  struct CallGuard;
  bool enter_call(void* callee, bool generic);
  // The size guard: str-cat, create$, ... replaced in this environment by evaluators that check
  // the result's size before CLIPS builds it (environment.cpp).
  struct SizeGuard;

  void* env_ = nullptr;
  std::uint64_t code_version_ = 0;
  OutputHandler output_;
  std::deque<FunctionEntry> functions_;  // stable addresses: CLIPS holds pointers to them
  std::map<std::string, std::string, std::less<>> forbidden_;  // forbid_function: name -> why
  // Error capture while loading: werror text and where each message started.
  bool loading_ = false;
  std::string load_errors_;
  std::vector<std::pair<std::size_t, int>> error_starts_;  // (offset in load_errors_, line)
  // The work budget (start_budget).
  std::int64_t steps_ = 0;
  std::int64_t max_steps_ = 0;  // 0: no budget
  double max_wall_s_ = 0.0;
  std::chrono::steady_clock::time_point budget_start_;
  BudgetHit budget_hit_ = BudgetHit::kNone;
  // The trace (observe()).
  TraceObserver* observer_ = nullptr;
  bool observe_rules_ = false;
  bool observe_facts_ = false;
  bool fact_texts_ = true;
  std::vector<std::int64_t> matched_;       // reused for on_fire
  mutable std::string* capture_ = nullptr;  // print_fact: where the capture router writes
  std::string fact_buf_;                    // reused for on_fact
  int max_call_depth_ = 0;                  // 0: no limit
  int call_depth_ = 0;
  std::string budget_function_;
  std::unique_ptr<CallGuard> guard_;
  SizeLimits limits_;
  std::int64_t budget_memory_ = 0;
  std::unique_ptr<SizeGuard> sizes_;
};

}  // namespace llsf::clips::detail
