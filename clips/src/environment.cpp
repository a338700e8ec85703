// SPDX-License-Identifier: MIT
// Environment: the one translation unit that includes the CLIPS 6.30 headers. Everything CLIPS-
// specific (DATA_OBJECT, routers, string sources, fact slots, the 6.30 Env* API) stays here.
#include "environment.h"

#include <algorithm>
#include <stdexcept>

// CLIPS 6.30 is C without extern "C" guards; its macros must come after all C++ headers.
extern "C" {
#include <clips/clips.h>
}

namespace llsf::clips::detail {

namespace {

constexpr const char* kRouterName = "llsf-output";
constexpr const char* kLoadSource = "llsf-load";
constexpr const char* kCaptureName = "llsf-capture";  // print_fact(): text into a std::string
constexpr const char* kTraceHook = "llsf-trace";

// Logical names our router takes (CLIPS' own and Fawkes' log levels); string routers used by
// (format nil ...) and our load source are left alone.
bool is_output_name(const char* name) {
  static constexpr std::string_view kNames[] = {
      "t",      "stdout",  "wclips", "wdialog", "wdisplay", "werror", "wwarning",
      "wtrace", "wprompt", "debug",  "info",    "warn",     "error",  "l"};
  const std::string_view n(name);
  return std::find(std::begin(kNames), std::end(kNames), n) != std::end(kNames);
}

// A C function pointer cast to the type CLIPS stores (through void(*)() to keep
// -Wcast-function-type quiet: CLIPS calls it with the right signature).
template <class F>
int (*clips_fn(F* f))(void*) {
  return reinterpret_cast<int (*)(void*)>(reinterpret_cast<void (*)()>(f));
}

Value to_value(void* env, int type, void* value, const DATA_OBJECT* whole = nullptr) {
  switch (type) {
    case SYMBOL:
    case INSTANCE_NAME:
      return Value::symbol(ValueToString(value));
    case STRING:
      return Value::string(ValueToString(value));
    case INTEGER:
      return Value::integer_value(ValueToLong(value));
    case FLOAT:
      return Value::float_value(ValueToDouble(value));
    case EXTERNAL_ADDRESS:
      return Value::external(ValueToExternalAddress(value));
    case FACT_ADDRESS: {
      Value v;
      v.type = Value::Type::kFact;
      v.integer = EnvFactIndex(env, value);
      return v;
    }
    case MULTIFIELD: {
      std::vector<Value> items;
      if (whole != nullptr) {
        const long begin = GetpDOBegin(whole), end = GetpDOEnd(whole);
        for (long i = begin; i <= end; ++i)
          items.push_back(to_value(env, GetMFType(value, i), GetMFValue(value, i)));
      } else {
        const long n = GetMFLength(value);
        for (long i = 1; i <= n; ++i)
          items.push_back(to_value(env, GetMFType(value, i), GetMFValue(value, i)));
      }
      return Value::multifield(std::move(items));
    }
    default:
      return {};
  }
}

Value to_value(void* env, const DATA_OBJECT& d) {
  return to_value(env, GetType(d), GetValue(d), &d);
}

// A single-field CLIPS atom for `v` (multifields are handled by the callers).
void atom(void* env, const Value& v, int& type, void*& value) {
  switch (v.type) {
    case Value::Type::kVoid:
      type = SYMBOL;
      value = EnvAddSymbol(env, "nil");
      return;
    case Value::Type::kSymbol:
      type = SYMBOL;
      value = EnvAddSymbol(env, v.text.c_str());
      return;
    case Value::Type::kString:
      type = STRING;
      value = EnvAddSymbol(env, v.text.c_str());
      return;
    case Value::Type::kInteger:
      type = INTEGER;
      value = EnvAddLong(env, v.integer);
      return;
    case Value::Type::kFloat:
      type = FLOAT;
      value = EnvAddDouble(env, v.real);
      return;
    case Value::Type::kAddress:
      type = EXTERNAL_ADDRESS;
      value = EnvAddExternalAddress(env, v.address, C_POINTER_EXTERNAL_ADDRESS);
      return;
    case Value::Type::kFact: {
      void* f = FindIndexedFact(env, v.integer);
      if (f != nullptr) {
        type = FACT_ADDRESS;
        value = f;
      } else {
        type = SYMBOL;
        value = EnvFalseSymbol(env);
      }
      return;
    }
    case Value::Type::kMultifield:
      type = SYMBOL;
      value = EnvAddSymbol(env, "nil");
      return;
  }
}

void to_data_object(void* env, const Value& v, DATA_OBJECT& out) {
  if (v.type == Value::Type::kMultifield) {
    const long n = static_cast<long>(v.items.size());
    void* mf = EnvCreateMultifield(env, n);
    for (long i = 1; i <= n; ++i) {
      int t = 0;
      void* val = nullptr;
      atom(env, v.items[static_cast<std::size_t>(i - 1)], t, val);
      SetMFType(mf, i, t);
      SetMFValue(mf, i, val);
    }
    SetType(out, MULTIFIELD);
    SetValue(out, mf);
    SetDOBegin(out, 1);
    SetDOEnd(out, n);
    return;
  }
  int t = 0;
  void* val = nullptr;
  atom(env, v, t, val);
  SetType(out, t);
  SetValue(out, val);
}

}  // namespace

// The router callbacks reach the Environment through the router context.
struct RouterAccess {
  static int query(void*, const char* name) {
    // print_fact() passes kCaptureName itself: a pointer compare first (many calls per fact).
    if (name == kCaptureName) return TRUE;
    return is_output_name(name) || std::string_view(name) == kCaptureName ? TRUE : FALSE;
  }
  static int print(void* env, const char* name, const char* text) {
    auto* self = static_cast<Environment*>(GetEnvironmentRouterContext(env));
    if (name == kCaptureName || std::string_view(name) == kCaptureName) {
      if (self->capture_ != nullptr) self->capture_->append(text);
      return TRUE;
    }
    try {
      self->on_print(name, text);
    } catch (...) {  // never through CLIPS' C frames (a throwing log sink loses the line)
    }
    return TRUE;
  }
  static int getc(void*, const char*) { return EOF; }
  static int ungetc(void*, int c, const char*) { return c; }
  static int exit(void*, int) { return TRUE; }

  // All user-defined functions go through this one entry point (context = FunctionEntry*).
  static void dispatch(void* env, DATA_OBJECT* rv) {
    auto* entry = static_cast<Environment::FunctionEntry*>(GetEnvironmentFunctionContext(env));
    Args args(*entry->self, env, entry->name);
    Value result;
    try {
      result = entry->fn(args);
    } catch (const std::exception& e) {
      entry->self->error(entry->name, e.what());
      result = Value::boolean(false);
    }
    if (result.type == Value::Type::kVoid) {
      SetpType(rv, RVOID);
      SetpValue(rv, EnvFalseSymbol(env));
      return;
    }
    to_data_object(env, result, *rv);
  }
};

// The trace hooks (Environment::observe); registered only while an observer is installed.
struct TraceHooks {
  static Environment* self(void* env) {
    return static_cast<Environment*>(GetEnvironmentContext(env));
  }
  // Before each firing: the activation's rule and the facts of its partial match (the basis).
  static void before_fire(void* env, void* activation) {
    Environment* e = self(env);
    if (e == nullptr || e->observer_ == nullptr) return;
    e->matched_.clear();
    const struct partialMatch* basis = EnvGetActivationBasis(env, activation);
    if (basis != nullptr) {
      for (unsigned i = 0; i < basis->bcount; ++i) {
        const struct alphaMatch* m = basis->binds[i].gm.theMatch;
        if (m == nullptr || m->matchingItem == nullptr ||
            m->matchingItem->theInfo != &FactData(env)->FactInfo)
          continue;  // a not/exists pattern (or an instance)
        e->matched_.push_back(reinterpret_cast<const struct fact*>(m->matchingItem)->factIndex);
      }
    }
    const char* name = EnvGetActivationName(env, activation);
    try {
      e->observer_->on_fire(name != nullptr ? name : "", e->matched_);
    } catch (...) {  // never through CLIPS' C frames
    }
  }
  static void changed(void* env, void* f, bool asserted) {
    Environment* e = self(env);
    if (e == nullptr || e->observer_ == nullptr) return;
    e->fact_buf_.clear();
    if (e->fact_texts_) e->print_fact(f, e->fact_buf_);
    try {
      e->observer_->on_fact(asserted, static_cast<struct fact*>(f)->factIndex, e->fact_buf_);
    } catch (...) {
    }
  }
  static void asserted(void* env, void* f) { changed(env, f, true); }
  static void retracted(void* env, void* f) { changed(env, f, false); }
};

// ---- Args ----------------------------------------------------------------------------------

int Args::count() const { return EnvRtnArgCount(clips_env_); }

Value::Type Args::type(int i) const { return value(i).type; }

Value Args::value(int i) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  return to_value(clips_env_, d);
}

bool Args::number(int i, double& out) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  if (GetType(d) == INTEGER) {
    out = static_cast<double>(DOToLong(d));
    return true;
  }
  if (GetType(d) == FLOAT) {
    out = DOToDouble(d);
    return true;
  }
  return false;
}

bool Args::integer(int i, std::int64_t& out) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  if (GetType(d) == INTEGER) {
    out = DOToLong(d);
    return true;
  }
  if (GetType(d) == FLOAT) {
    const double x = DOToDouble(d);
    if (x != static_cast<double>(static_cast<std::int64_t>(x))) return false;
    out = static_cast<std::int64_t>(x);
    return true;
  }
  return false;
}

bool Args::text(int i, std::string_view& out) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  if (GetType(d) != SYMBOL && GetType(d) != STRING && GetType(d) != INSTANCE_NAME) return false;
  out = DOToString(d);
  return true;
}

bool Args::address(int i, void*& out) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  if (GetType(d) != EXTERNAL_ADDRESS) return false;
  out = DOToPointer(d) == nullptr ? nullptr : ValueToExternalAddress(GetValue(d));
  return true;
}

bool Args::time(int i, double& seconds) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  auto num = [](int type, void* value, double& out) {
    if (type == INTEGER) {
      out = static_cast<double>(ValueToLong(value));
      return true;
    }
    if (type == FLOAT) {
      out = ValueToDouble(value);
      return true;
    }
    return false;
  };
  if (GetType(d) == MULTIFIELD) {
    const long begin = GetDOBegin(d), end = GetDOEnd(d);
    if (end - begin != 1) return false;
    double sec = 0, usec = 0;
    void* mf = GetValue(d);
    if (!num(GetMFType(mf, begin), GetMFValue(mf, begin), sec) ||
        !num(GetMFType(mf, end), GetMFValue(mf, end), usec))
      return false;
    seconds = sec + usec * 1e-6;
    return true;
  }
  return num(GetType(d), GetValue(d), seconds);
}

// ---- Template --------------------------------------------------------------------------------

int Template::slot_index(std::string_view slot) const {
  for (std::size_t i = 0; i < slots.size(); ++i)
    if (slots[i] == slot) return static_cast<int>(i);
  throw std::logic_error("deftemplate " + name + " has no slot " + std::string(slot));
}

// ---- Environment -----------------------------------------------------------------------------

Environment::Environment() {
  env_ = CreateEnvironment();
  if (env_ == nullptr) throw std::runtime_error("CLIPS: cannot create an environment");
  EnvAddRouterWithContext(env_, kRouterName, 40, &RouterAccess::query, &RouterAccess::print,
                          &RouterAccess::getc, &RouterAccess::ungetc, &RouterAccess::exit, this);
  SetEnvironmentContext(env_, this);
  EnvAddPeriodicFunction(env_, "llsf-budget", &Environment::periodic, 0);
}

void Environment::periodic(void* clips_env) {
  auto* self = static_cast<Environment*>(GetEnvironmentContext(clips_env));
  if (self == nullptr || self->max_steps_ <= 0) return;
  ++self->steps_;
  if (self->budget_hit_ == BudgetHit::kNone) {
    if (self->steps_ > self->max_steps_) {
      self->budget_hit_ = BudgetHit::kSteps;
    } else if ((self->steps_ & 1023) == 0) {
      // The wall clock only cuts runaway work (it never changes a game that stays in budget).
      const std::chrono::duration<double> spent =
          std::chrono::steady_clock::now() - self->budget_start_;
      if (spent.count() > self->max_wall_s_) self->budget_hit_ = BudgetHit::kWall;
    }
  }
  if (self->budget_hit_ != BudgetHit::kNone) SetHaltExecution(clips_env, TRUE);
}

void Environment::start_budget(std::int64_t max_steps, double max_wall_s) {
  steps_ = 0;
  max_steps_ = max_steps;
  max_wall_s_ = max_wall_s;
  budget_hit_ = BudgetHit::kNone;
  budget_start_ = std::chrono::steady_clock::now();
}

std::string Environment::next_rule() const {
  void* act = EnvGetNextActivation(env_, nullptr);
  if (act == nullptr) return {};
  const char* name = EnvGetActivationName(env_, act);
  return name != nullptr ? std::string(name) : std::string();
}

Environment::~Environment() { DestroyEnvironment(env_); }

void Environment::on_print(std::string_view logical_name, std::string_view text) {
  if (loading_ && logical_name == "werror") {
    // A message starts with "[ID]" at the beginning of a line: remember where and on which line.
    if (!text.empty() && text.front() == '[' &&
        (load_errors_.empty() || load_errors_.back() == '\n'))
      error_starts_.emplace_back(load_errors_.size(), static_cast<int>(GetLineCount(env_)));
    load_errors_.append(text);
    return;
  }
  if (output_) output_(logical_name, text);
}

void Environment::define_function(const std::string& name, const std::string& restrictions,
                                  Function fn) {
  functions_.push_back(FunctionEntry{this, name, restrictions, std::move(fn)});
  FunctionEntry& e = functions_.back();
  // CLIPS keeps the restriction string's pointer: it lives in the entry (stable in a deque).
  if (!EnvDefineFunction2WithContext(env_, e.name.c_str(), 'u', clips_fn(&RouterAccess::dispatch),
                                     "llsf_clips_dispatch",
                                     e.restrictions.empty() ? nullptr : e.restrictions.c_str(), &e))
    throw std::logic_error("CLIPS: cannot define function " + name);
}

void Environment::error(std::string_view function, std::string_view message) {
  std::string text = "[LLSF1] ";
  text.append(function).append(": ").append(message).append("\n");
  EnvPrintRouter(env_, WERROR, text.c_str());
  SetEvaluationError(env_, TRUE);
}

namespace {

// Compresses one CLIPS error message: "[ID] text" + "ERROR:" + the construct echo up to the
// error becomes "[ID] text (in defrule MAIN::x)".
std::string compress_error(std::string_view raw) {
  std::string head(raw.substr(0, raw.find("ERROR:")));
  std::string construct;
  if (auto pos = raw.find("ERROR:"); pos != std::string_view::npos) {
    std::string_view rest = raw.substr(pos + 6);
    const auto start = rest.find('(');
    if (start != std::string_view::npos) {
      rest = rest.substr(start + 1);
      construct = std::string(rest.substr(0, rest.find_first_of("\n")));
    }
  }
  std::string out;
  bool space = false;
  for (char c : head) {
    if (c == '\n' || c == '\r' || c == ' ' || c == '\t') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += c;
  }
  // Keep only the construct's kind and name ("defrule MAIN::b").
  if (!construct.empty()) {
    std::string kind_name;
    int words = 0;
    bool in_word = false;
    for (char c : construct) {
      const bool sep = c == ' ' || c == '\t' || c == '(' || c == ')';
      if (sep) {
        if (in_word && ++words == 2) break;
        in_word = false;
        continue;
      }
      if (!in_word && !kind_name.empty()) kind_name += ' ';
      in_word = true;
      kind_name += c;
    }
    out += " (in " + kind_name + ")";
  }
  return out;
}

}  // namespace

std::vector<LoadError> Environment::load(const std::string& text) {
  loading_ = true;
  load_errors_.clear();
  error_starts_.clear();
  OpenStringSource(env_, kLoadSource, text.c_str(), 0);
  // Count lines on our string source as CLIPS does for files it loads itself.
  RouterData(env_)->LineCountRouter = kLoadSource;
  SetLineCount(env_, 1);
  const int ok = LoadConstructsFromLogicalName(env_, kLoadSource);
  RouterData(env_)->LineCountRouter = nullptr;
  const int last_line = static_cast<int>(GetLineCount(env_));
  CloseStringSource(env_, kLoadSource);
  loading_ = false;

  std::vector<LoadError> errors;
  for (std::size_t i = 0; i < error_starts_.size(); ++i) {
    const std::size_t begin = error_starts_[i].first;
    const std::size_t end =
        i + 1 < error_starts_.size() ? error_starts_[i + 1].first : load_errors_.size();
    errors.push_back({error_starts_[i].second,
                      compress_error(std::string_view(load_errors_).substr(begin, end - begin))});
  }
  if (errors.empty() && !load_errors_.empty())
    errors.push_back({last_line, compress_error(load_errors_)});
  if (errors.empty() && ok != 1) errors.push_back({last_line, "CLIPS could not load the code"});
  return errors;
}

void Environment::build(const std::string& construct) {
  const auto errors = load(construct);
  if (!errors.empty()) throw std::logic_error("CLIPS: built-in construct: " + errors[0].message);
}

Template Environment::find_template(const std::string& name) {
  Template t;
  t.ptr = EnvFindDeftemplate(env_, name.c_str());
  if (t.ptr == nullptr) throw std::logic_error("CLIPS: no deftemplate " + name);
  t.name = name;
  t.implied = static_cast<struct deftemplate*>(t.ptr)->implied;
  if (!t.implied) {
    DATA_OBJECT names;
    EnvDeftemplateSlotNames(env_, t.ptr, &names);
    const Value v = to_value(env_, names);
    for (const auto& s : v.items) t.slots.push_back(s.text);
  }
  return t;
}

FactHandle Environment::assert_fact(const Template& t, std::span<const Value> values) {
  void* fact = EnvCreateFact(env_, t.ptr);
  if (fact == nullptr) throw std::logic_error("CLIPS: cannot create a fact of " + t.name);
  DATA_OBJECT d;
  if (t.implied) {
    to_data_object(env_, Value::multifield({values.begin(), values.end()}), d);
    EnvPutFactSlot(env_, fact, nullptr, &d);
  } else {
    EnvAssignFactSlotDefaults(env_, fact);
    const std::size_t n = std::min(values.size(), t.slots.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (values[i].type == Value::Type::kVoid) continue;
      to_data_object(env_, values[i], d);
      if (!EnvPutFactSlot(env_, fact, t.slots[i].c_str(), &d))
        throw std::logic_error("CLIPS: cannot set slot " + t.slots[i] + " of " + t.name);
    }
  }
  FactHandle h;
  void* asserted = EnvAssert(env_, fact);
  if (asserted != nullptr) {
    EnvIncrementFactCount(env_, asserted);
    h.fact_ = asserted;
  }
  return h;
}

bool Environment::exists(const FactHandle& h) const {
  return h.fact_ != nullptr && EnvFactExistp(env_, h.fact_);
}

void Environment::retract(FactHandle& h) {
  if (h.fact_ == nullptr) return;
  if (EnvFactExistp(env_, h.fact_)) EnvRetract(env_, h.fact_);
  release(h);
}

void Environment::release(FactHandle& h) {
  if (h.fact_ == nullptr) return;
  EnvDecrementFactCount(env_, h.fact_);
  h.fact_ = nullptr;
}

bool Environment::assert_string(const std::string& fact) {
  return EnvAssertString(env_, fact.c_str()) != nullptr;
}

std::int64_t Environment::run(std::int64_t limit) { return EnvRun(env_, limit); }

bool Environment::agenda_empty() const { return EnvGetNextActivation(env_, nullptr) == nullptr; }

bool Environment::halted() const {
  return GetHaltExecution(env_) != 0 || GetEvaluationError(env_) != 0;
}

void Environment::clear_halt() {
  SetHaltExecution(env_, FALSE);
  SetEvaluationError(env_, FALSE);
}

void Environment::reset() { EnvReset(env_); }

void Environment::set_global(const std::string& name, const Value& v) {
  DATA_OBJECT d;
  to_data_object(env_, v, d);
  if (!EnvSetDefglobalValue(env_, name.c_str(), &d))
    throw std::logic_error("CLIPS: no defglobal " + name);
}

Value Environment::eval(const std::string& expression) {
  DATA_OBJECT d;
  if (!EnvEval(env_, expression.c_str(), &d)) return {};
  return to_value(env_, d);
}

std::vector<FactCopy> Environment::facts(std::string_view template_name) const {
  std::vector<FactCopy> out;
  for (void* f = EnvGetNextFact(env_, nullptr); f != nullptr; f = EnvGetNextFact(env_, f)) {
    void* tmpl = EnvFactDeftemplate(env_, f);
    const char* name = EnvGetDeftemplateName(env_, tmpl);
    if (!template_name.empty() && template_name != name) continue;
    FactCopy copy;
    copy.index = EnvFactIndex(env_, f);
    copy.template_name = name;
    DATA_OBJECT d;
    if (static_cast<struct deftemplate*>(tmpl)->implied) {
      EnvGetFactSlot(env_, f, nullptr, &d);
      copy.slots.emplace_back("", to_value(env_, d));
    } else {
      DATA_OBJECT names;
      EnvDeftemplateSlotNames(env_, tmpl, &names);
      const Value slot_names = to_value(env_, names);
      for (const auto& s : slot_names.items) {
        EnvGetFactSlot(env_, f, s.text.c_str(), &d);
        copy.slots.emplace_back(s.text, to_value(env_, d));
      }
    }
    out.push_back(std::move(copy));
  }
  return out;
}

void Environment::observe(TraceObserver* observer, bool rules, bool facts, bool fact_texts) {
  if (observe_rules_) EnvRemoveBeforeRunFunction(env_, kTraceHook);
  if (observe_facts_) {
    EnvRemoveAssertFunction(env_, kTraceHook);
    EnvRemoveRetractFunction(env_, kTraceHook);
  }
  observer_ = observer;
  observe_rules_ = observer != nullptr && rules;
  observe_facts_ = observer != nullptr && facts;
  fact_texts_ = fact_texts;
  if (observe_rules_) EnvAddBeforeRunFunction(env_, kTraceHook, &TraceHooks::before_fire, 0);
  if (observe_facts_) {
    EnvAddAssertFunction(env_, kTraceHook, &TraceHooks::asserted, 0);
    EnvAddRetractFunction(env_, kTraceHook, &TraceHooks::retracted, 0);
  }
}

void Environment::print_fact(void* fact, std::string& out) const {
  std::string* before = capture_;
  capture_ = &out;
  PrintFact(env_, kCaptureName, static_cast<struct fact*>(fact), FALSE, FALSE);
  capture_ = before;
}

std::string Environment::fact_text(std::int64_t index) const {
  std::string out;
  for (void* f = EnvGetNextFact(env_, nullptr); f != nullptr; f = EnvGetNextFact(env_, f)) {
    if (EnvFactIndex(env_, f) == index) {
      print_fact(f, out);
      break;
    }
  }
  return out;
}

void Environment::fact_texts(std::vector<std::pair<std::int64_t, std::string>>& out,
                             std::int64_t from_index) const {
  out.clear();
  // Facts are appended to the list with increasing indices (a reset restarts both).
  struct fact* first = FactData(env_)->LastFact;
  if (first == nullptr || first->factIndex < from_index) return;
  while (first->previousFact != nullptr && first->previousFact->factIndex >= from_index)
    first = first->previousFact;
  for (struct fact* f = first; f != nullptr; f = f->nextFact) {
    out.emplace_back(f->factIndex, std::string());
    print_fact(f, out.back().second);
  }
}

}  // namespace llsf::clips::detail
