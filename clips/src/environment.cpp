// SPDX-License-Identifier: MIT
// Environment: the one translation unit that includes the CLIPS 6.30 headers. Everything CLIPS-
// specific (DATA_OBJECT, routers, string sources, fact slots, the 6.30 Env* API) stays here.
#include "environment.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <regex>
#include <stdexcept>

#include "source_text.h"

// CLIPS 6.30 is C without extern "C" guards; its macros must come after all C++ headers.
extern "C" {
#include <clips/clips.h>
#include <clips/tmpltutl.h>  // CreateImpliedDeftemplate
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
      // TRUE and FALSE (every predicate's result) without hashing them into the symbol table.
      if (v.text.size() == 4 && std::memcmp(v.text.data(), "TRUE", 4) == 0)
        value = EnvTrueSymbol(env);
      else if (v.text.size() == 5 && std::memcmp(v.text.data(), "FALSE", 5) == 0)
        value = EnvFalseSymbol(env);
      else
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

// A multifield of atoms for a fact slot (what DOToMultifield makes of a DATA_OBJECT: not on the
// garbage list, owned by the fact once asserted).
void* make_multifield(void* env, std::span<const Value> items) {
  const long n = static_cast<long>(items.size());
  void* mf = CreateMultifield2(env, n);
  for (long i = 1; i <= n; ++i) {
    int t = 0;
    void* val = nullptr;
    atom(env, items[static_cast<std::size_t>(i - 1)], t, val);
    SetMFType(mf, i, t);
    SetMFValue(mf, i, val);
  }
  return mf;
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
  // CLIPS ends the process (exit(code) follows): an agent's (exit) with the sandbox off, or one
  // of CLIPS' internal errors. Say so on stderr, as nothing else would.
  static int exit(void*, int code) {
    char text[256];
    const int n =
        std::snprintf(text, sizeof text,
                      "llsfsim: CLIPS ends the process with exit code %d: an agent called "
                      "(exit) with robots.sandbox false, or CLIPS hit an internal error "
                      "(docs/security.md)\n",
                      code);
    if (n > 0) (void)!::write(2, text, std::min(static_cast<std::size_t>(n), sizeof text - 1));
    return TRUE;
  }

  // All user-defined functions go through this one entry point (context = FunctionEntry*).
  static void dispatch(void* env, DATA_OBJECT* rv) {
    auto* entry = static_cast<Environment::FunctionEntry*>(GetEnvironmentFunctionContext(env));
    Args args(*entry->self, env, entry->name, rv);
    Value result;
    try {
      result = entry->fn(args);
    } catch (const std::exception& e) {
      entry->self->error(entry->name, e.what());
      result = Value::boolean(false);
    }
    if (args.returned() && result.type == Value::Type::kVoid) return;
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

ArgView Args::view(int i) const {
  DATA_OBJECT d;
  EnvRtnUnknown(clips_env_, i + 1, &d);
  ArgView v;
  switch (GetType(d)) {
    case SYMBOL:
    case INSTANCE_NAME:
      v.type = Value::Type::kSymbol;
      v.text = DOToString(d);
      break;
    case STRING:
      v.type = Value::Type::kString;
      v.text = DOToString(d);
      break;
    case INTEGER:
      v.type = Value::Type::kInteger;
      v.integer = DOToLong(d);
      break;
    case FLOAT:
      v.type = Value::Type::kFloat;
      v.real = DOToDouble(d);
      break;
    case EXTERNAL_ADDRESS:
      v.type = Value::Type::kAddress;
      v.address = DOToPointer(d) == nullptr ? nullptr : ValueToExternalAddress(GetValue(d));
      break;
    default:  // multifields and facts: copied
      v.whole = to_value(clips_env_, d);
      v.type = v.whole.type;
  }
  return v;
}

Value ArgView::to_value() const {
  switch (type) {
    case Value::Type::kSymbol:
      return Value::symbol(std::string(text));
    case Value::Type::kString:
      return Value::string(std::string(text));
    case Value::Type::kInteger:
      return Value::integer_value(integer);
    case Value::Type::kFloat:
      return Value::float_value(real);
    case Value::Type::kAddress:
      return Value::external(address);
    default:
      return whole;
  }
}

void Args::return_symbol(const char* text) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, SYMBOL);
  SetpValue(rv, EnvAddSymbol(clips_env_, text));
  returned_ = true;
}

void Args::return_string(const char* text) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, STRING);
  SetpValue(rv, EnvAddSymbol(clips_env_, text));
  returned_ = true;
}

void Args::return_integer(std::int64_t i) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, INTEGER);
  SetpValue(rv, EnvAddLong(clips_env_, i));
  returned_ = true;
}

void Args::return_float(double d) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, FLOAT);
  SetpValue(rv, EnvAddDouble(clips_env_, d));
  returned_ = true;
}

void Args::return_external(void* p) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, EXTERNAL_ADDRESS);
  SetpValue(rv, EnvAddExternalAddress(clips_env_, p, C_POINTER_EXTERNAL_ADDRESS));
  returned_ = true;
}

void Args::return_boolean(bool b) {
  auto* rv = static_cast<DATA_OBJECT*>(result_);
  SetpType(rv, SYMBOL);
  SetpValue(rv, b ? EnvTrueSymbol(clips_env_) : EnvFalseSymbol(clips_env_));
  returned_ = true;
}

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

// CLIPS evaluates a deffunction call (PCALL) and a generic function call (GCALL) through the
// entity record registered for that type in this environment's PrimitivesArray. The guard puts a
// copy of each record there whose evaluator counts the call as a budget step and the nesting
// depth, then calls CLIPS' own evaluator. (A recursion never returns to CLIPS' periodic
// callbacks, so without this a deffunction calling itself ends with the C stack: SIGSEGV.)
struct Environment::CallGuard {
  struct entityRecord pcall {};
  struct entityRecord gcall {};
  intBool (*pcall_eval)(void*, void*, DATA_OBJECT*) = nullptr;
  intBool (*gcall_eval)(void*, void*, DATA_OBJECT*) = nullptr;

  void install(void* clips_env) {
    auto& prims = EvaluationData(clips_env)->PrimitivesArray;
    if (prims[PCALL] != nullptr && prims[PCALL]->evaluateFunction != nullptr) {
      pcall = *prims[PCALL];
      pcall_eval = pcall.evaluateFunction;
      pcall.evaluateFunction = &CallGuard::deffunction_call;
      prims[PCALL] = &pcall;
    }
    if (prims[GCALL] != nullptr && prims[GCALL]->evaluateFunction != nullptr) {
      gcall = *prims[GCALL];
      gcall_eval = gcall.evaluateFunction;
      gcall.evaluateFunction = &CallGuard::generic_call;
      prims[GCALL] = &gcall;
    }
  }
  static intBool call(void* clips_env, void* callee, DATA_OBJECT* result, bool generic) {
    auto* self = static_cast<Environment*>(GetEnvironmentContext(clips_env));
    if (!self->enter_call(callee, generic)) {
      result->type = SYMBOL;
      result->value = EnvFalseSymbol(clips_env);
      return FALSE;
    }
    const auto eval = generic ? self->guard_->gcall_eval : self->guard_->pcall_eval;
    const intBool ok = eval(clips_env, callee, result);
    --self->call_depth_;
    return ok;
  }
  static intBool deffunction_call(void* clips_env, void* callee, DATA_OBJECT* result) {
    return call(clips_env, callee, result, false);
  }
  static intBool generic_call(void* clips_env, void* callee, DATA_OBJECT* result) {
    return call(clips_env, callee, result, true);
  }
};

// The size guard. CLIPS calls a function through its FunctionDefinition's functionPointer (with
// the definition's context as the function context). The guard points the definitions of the
// functions that build strings and multifields at its own evaluators: they evaluate the call's
// arguments once (protected with ValueInstall while the next ones are evaluated), bound the size
// of the result from those values and, within the budgets, run CLIPS' own function on a copy of
// the call whose arguments are the values as constants (CLIPS evaluates a MULTIFIELD constant to
// the DATA_OBJECT it points to). So CLIPS' behaviour is unchanged for every call within budget,
// and a call past one never allocates: str-cat sums its lengths in an int, a 2 GB string wraps.
struct Environment::SizeGuard {
  enum class Kind : std::uint8_t {
    kConcat,         // str-cat, sym-cat: the arguments' printed lengths
    kImplode,        // implode$, str-implode: each field quoted and escaped, plus spaces
    kFormat,         // format: the control string, its widths and the arguments
    kPrint,          // printout: what it prints
    kFields,         // create$, insert$, replace$, mv-append, mv-replace: the fields of all args
    kExplode,        // explode$, str-explode: at most one field per two characters
    kReplaceMember,  // replace-member$: each field may become the whole replacement
    kCompare,        // subsetp, member$, delete-member$: fields of the first x fields of the rest
  };
  struct Builder {
    Environment* self;
    std::string name;
    Kind kind;
    char type;              // CLIPS' return type code of the function
    int (*original)(void);  // CLIPS' own function
    void* original_context;
  };
  std::deque<Builder> builders;  // stable addresses: the definitions' contexts point at them

  static constexpr std::pair<const char*, Kind> kFunctions[] = {
      {"str-cat", Kind::kConcat},         {"sym-cat", Kind::kConcat},
      {"implode$", Kind::kImplode},       {"str-implode", Kind::kImplode},
      {"format", Kind::kFormat},          {"printout", Kind::kPrint},
      {"create$", Kind::kFields},         {"mv-append", Kind::kFields},
      {"insert$", Kind::kFields},         {"replace$", Kind::kFields},
      {"mv-replace", Kind::kFields},      {"explode$", Kind::kExplode},
      {"str-explode", Kind::kExplode},    {"replace-member$", Kind::kReplaceMember},
      {"subsetp", Kind::kCompare},        {"member$", Kind::kCompare},
      {"delete-member$", Kind::kCompare},
  };
  // Field comparisons one kCompare call may make, per field of the multifield budget: with the
  // default budget 10^8 comparisons (well under a second); subsetp of two 1,000,000-field
  // multifields (10^12) ran for many minutes inside one call, where no step is counted.
  static constexpr std::int64_t kComparesPerField = 100;

  void install(Environment& self, void* clips_env) {
    for (const auto& [name, kind] : kFunctions) guard(self, clips_env, name, kind);
  }
  // Points the definition of `name` (if CLIPS has it) at the evaluator for its return type.
  void guard(Environment& self, void* clips_env, const char* name, Kind kind) {
    struct FunctionDefinition* fd = FindFunction(clips_env, name);
    if (fd == nullptr || !fd->environmentAware) return;
    int (*evaluator)(void) = nullptr;
    switch (fd->returnValueType) {
      case 'v':
        evaluator = reinterpret_cast<int (*)(void)>(reinterpret_cast<void (*)()>(&call_print));
        break;
      case 'b':
        evaluator = reinterpret_cast<int (*)(void)>(reinterpret_cast<void (*)()>(&call_bool));
        break;
      case 's':
      case 'w':
        evaluator = reinterpret_cast<int (*)(void)>(reinterpret_cast<void (*)()>(&call_symbol));
        break;
      case 'j':
      case 'k':
      case 'm':
      case 'n':
      case 'u':
        evaluator = reinterpret_cast<int (*)(void)>(reinterpret_cast<void (*)()>(&call_value));
        break;
      default:
        throw std::logic_error(std::string("CLIPS: cannot guard function ") + name);
    }
    builders.push_back(
        Builder{&self, name, kind, fd->returnValueType, fd->functionPointer, fd->context});
    fd->functionPointer = evaluator;
    fd->context = &builders.back();
  }

  // The printed length of an atom (a bound for numbers and addresses).
  static std::int64_t text_length(int type, void* value) {
    switch (type) {
      case SYMBOL:
      case STRING:
      case INSTANCE_NAME:
        return static_cast<std::int64_t>(std::strlen(ValueToString(value)));
      case INTEGER:
      case FLOAT:
        return 32;
      default:
        return 64;
    }
  }
  static std::int64_t fields(const DATA_OBJECT& d) {
    return d.type == MULTIFIELD ? d.end - d.begin + 1 : 1;
  }
  // The printed length of a value; a multifield's fields with a separator each, and 2 for ().
  static std::int64_t printed_length(const DATA_OBJECT& d, bool quoted) {
    if (d.type != MULTIFIELD) {
      const std::int64_t n = text_length(d.type, d.value);
      return quoted && d.type == STRING ? 2 * n + 2 : n;
    }
    std::int64_t n = 2;
    for (long i = GetDOBegin(d), end = GetDOEnd(d); i <= end; ++i) {  // 1-based
      const std::int64_t len = text_length(GetMFType(d.value, i), GetMFValue(d.value, i));
      n += 1 + (quoted && GetMFType(d.value, i) == STRING ? 2 * len + 2 : len);
    }
    return n;
  }
  // The format control string's widths and precisions (all digit runs after a %).
  static std::int64_t format_widths(const char* control) {
    std::int64_t sum = 0;
    for (const char* c = control; *c != '\0'; ++c) {
      if (*c != '%') continue;
      std::int64_t number = 0;
      for (++c; *c != '\0' && std::strchr("0123456789.-+# ", *c) != nullptr; ++c) {
        if (*c >= '0' && *c <= '9') {
          number = std::min<std::int64_t>(number * 10 + (*c - '0'), std::int64_t{1} << 40);
        } else {
          sum += number;
          number = 0;
        }
      }
      sum += number;
      if (*c == '\0') break;
    }
    return sum;
  }

  // The result's size in characters (`chars`) or fields; false if it is past a budget (then the
  // error has been reported).
  static bool within_budget(const Builder& b, void* clips_env, const DATA_OBJECT* args, int n) {
    std::int64_t chars = -1, count = -1, compares = -1;
    switch (b.kind) {
      case Kind::kConcat:
      case Kind::kPrint:  // (call_print checks its own sum)
        chars = 0;
        for (int i = 0; i < n; ++i) chars += printed_length(args[i], false);
        break;
      case Kind::kImplode:
        chars = 0;
        for (int i = 0; i < n; ++i) chars += printed_length(args[i], true);
        break;
      case Kind::kFormat:
        chars = 0;
        for (int i = 1; i < n; ++i) chars += printed_length(args[i], false);
        if (n >= 2 && (args[1].type == STRING || args[1].type == SYMBOL))
          chars += format_widths(ValueToString(args[1].value));
        break;
      case Kind::kFields:
        count = 0;
        for (int i = 0; i < n; ++i) count += fields(args[i]);
        break;
      case Kind::kExplode:
        count = n >= 1 ? printed_length(args[0], false) / 2 + 1 : 0;
        break;
      case Kind::kReplaceMember:
        count = n >= 2 ? fields(args[0]) * std::max<std::int64_t>(1, fields(args[1])) : 0;
        break;
      case Kind::kCompare: {
        std::int64_t rest = 0;
        for (int i = 1; i < n; ++i) rest += fields(args[i]);
        compares = n >= 1 ? fields(args[0]) * rest : 0;
        break;
      }
    }
    Environment& self = *b.self;
    const SizeLimits& limits = self.limits_;
    std::string why;
    if (compares >= 0) {
      const std::int64_t max = limits.multifield_length * kComparesPerField;
      if (limits.multifield_length > 0 && compares > max)
        why = "up to " + std::to_string(compares) + " field comparisons, more than " +
              std::to_string(max) + " (" + std::to_string(kComparesPerField) +
              " x max_multifield_length)";
    } else if (chars >= 0 && limits.string_length > 0 && chars > limits.string_length) {
      why = (b.kind == Kind::kPrint ? "would print up to " : "the result would have up to ") +
            std::to_string(chars) + " characters, more than the string budget of " +
            std::to_string(limits.string_length) + " (max_string_length)";
    } else if (count >= 0 && limits.multifield_length > 0 && count > limits.multifield_length) {
      why = "the result would have up to " + std::to_string(count) +
            " fields, more than the multifield budget of " +
            std::to_string(limits.multifield_length) + " (max_multifield_length)";
    } else if (limits.memory_bytes > 0) {
      const std::int64_t bytes =
          chars >= 0 ? chars : count * static_cast<std::int64_t>(sizeof(struct field));
      const std::int64_t used = EnvMemUsed(clips_env);
      if (used + bytes > limits.memory_bytes)
        why = "the result would take up to " + std::to_string(bytes) + " bytes where CLIPS holds " +
              std::to_string(used) + ", more than the memory budget of " +
              std::to_string(limits.memory_bytes) + " bytes (max_memory_bytes)";
    }
    if (why.empty()) return true;
    self.error(b.name, why + "; the game goes on");
    return false;
  }

  // Evaluates the arguments, checks the budgets and calls CLIPS' function on the values; false
  // if it was not called (an argument failed or a budget was hit).
  template <class Call>
  static bool guarded(void* clips_env, Call&& original) {
    auto* b = static_cast<Builder*>(GetEnvironmentFunctionContext(clips_env));
    struct expr* const call = EvaluationData(clips_env)->CurrentExpression;
    int n = 0;
    for (struct expr* a = call->argList; a != nullptr; a = a->nextArg) ++n;
    constexpr int kInline = 8;
    DATA_OBJECT inline_values[kInline];
    struct expr inline_exprs[kInline];
    std::unique_ptr<DATA_OBJECT[]> heap_values;
    std::unique_ptr<struct expr[]> heap_exprs;
    DATA_OBJECT* values = inline_values;
    struct expr* exprs = inline_exprs;
    if (n > kInline) {
      heap_values = std::make_unique<DATA_OBJECT[]>(static_cast<std::size_t>(n));
      heap_exprs = std::make_unique<struct expr[]>(static_cast<std::size_t>(n));
      values = heap_values.get();
      exprs = heap_exprs.get();
    }
    int installed = 0;
    bool ok = true;
    for (struct expr* a = call->argList; a != nullptr; a = a->nextArg) {
      DATA_OBJECT& v = values[installed];
      EvaluateExpression(clips_env, a, &v);
      if (EvaluationData(clips_env)->EvaluationError || EvaluationData(clips_env)->HaltExecution) {
        ok = false;
        break;
      }
      ValueInstall(clips_env, &v);  // kept while the next arguments are evaluated
      ++installed;
    }
    if (ok) ok = within_budget(*b, clips_env, values, n);
    if (ok) {
      for (int i = 0; i < n; ++i) {
        exprs[i].type = values[i].type;
        exprs[i].value =
            values[i].type == MULTIFIELD ? static_cast<void*>(&values[i]) : values[i].value;
        exprs[i].argList = nullptr;
        exprs[i].nextArg = i + 1 < n ? &exprs[i + 1] : nullptr;
      }
      struct expr with_values = *call;
      with_values.argList = n > 0 ? &exprs[0] : nullptr;
      EvaluationData(clips_env)->CurrentExpression = &with_values;
      SetEnvironmentFunctionContext(clips_env, b->original_context);
      original(b);
      SetEnvironmentFunctionContext(clips_env, b);
      EvaluationData(clips_env)->CurrentExpression = call;
    }
    for (int i = 0; i < installed; ++i) ValueDeinstall(clips_env, &values[i]);
    return ok;
  }
  // printout prints each argument right after evaluating it (a deffunction in its arguments may
  // print too): CLIPS' printout is called once per argument, with the logical name, so the
  // output and its order stay CLIPS' own; what one call prints is summed against the budget.
  static void call_print(void* clips_env) {
    auto* b = static_cast<Builder*>(GetEnvironmentFunctionContext(clips_env));
    struct expr* const call = EvaluationData(clips_env)->CurrentExpression;
    const auto print = [&](struct expr* args) {
      struct expr with_values = *call;
      with_values.argList = args;
      EvaluationData(clips_env)->CurrentExpression = &with_values;
      SetEnvironmentFunctionContext(clips_env, b->original_context);
      reinterpret_cast<void (*)(void*)>(reinterpret_cast<void (*)()>(b->original))(clips_env);
      SetEnvironmentFunctionContext(clips_env, b);
      EvaluationData(clips_env)->CurrentExpression = call;
    };
    struct expr* const first = call->argList;
    if (first == nullptr || first->nextArg == nullptr) {
      print(first);
      return;
    }
    const auto failed = [clips_env] {
      return EvaluationData(clips_env)->EvaluationError || EvaluationData(clips_env)->HaltExecution;
    };
    DATA_OBJECT name;
    EvaluateExpression(clips_env, first, &name);
    if (failed()) return;
    ValueInstall(clips_env, &name);
    struct expr name_expr {};
    struct expr piece {};
    name_expr.type = name.type;
    name_expr.value = name.type == MULTIFIELD ? static_cast<void*>(&name) : name.value;
    name_expr.nextArg = &piece;
    // A logical name no router takes: CLIPS' printout reports it once and prints nothing (called
    // per argument, it would report it once per argument).
    if (name.type == SYMBOL || name.type == STRING) {
      const std::string_view logical = ValueToString(name.value);
      if (logical != "t" && logical != "nil" &&
          QueryRouters(clips_env, ValueToString(name.value)) == FALSE) {
        name_expr.nextArg = first->nextArg;
        print(&name_expr);
        ValueDeinstall(clips_env, &name);
        return;
      }
    }
    const std::int64_t limit = b->self->limits_.string_length;
    std::int64_t printed = 0;
    for (struct expr* a = first->nextArg; a != nullptr; a = a->nextArg) {
      DATA_OBJECT v;
      EvaluateExpression(clips_env, a, &v);
      if (failed()) break;
      printed += printed_length(v, false);
      if (limit > 0 && printed > limit) {
        b->self->error(b->name, "would print up to " + std::to_string(printed) +
                                    " characters, more than the string budget of " +
                                    std::to_string(limit) +
                                    " (max_string_length); the game goes on");
        break;
      }
      ValueInstall(clips_env, &v);
      piece.type = v.type;
      piece.value = v.type == MULTIFIELD ? static_cast<void*>(&v) : v.value;
      print(&name_expr);
      ValueDeinstall(clips_env, &v);
      if (failed()) break;
    }
    ValueDeinstall(clips_env, &name);
  }
  static void* call_symbol(void* clips_env) {
    void* result = nullptr;
    const bool called = guarded(clips_env, [clips_env, &result](Builder* b) {
      result =
          reinterpret_cast<void* (*)(void*)>(reinterpret_cast<void (*)()>(b->original))(clips_env);
    });
    return called ? result : EnvAddSymbol(clips_env, "");
  }
  static int call_bool(void* clips_env) {
    int result = FALSE;
    const bool called = guarded(clips_env, [clips_env, &result](Builder* b) {
      result =
          reinterpret_cast<int (*)(void*)>(reinterpret_cast<void (*)()>(b->original))(clips_env);
    });
    return called ? result : FALSE;
  }
  static void call_value(void* clips_env, DATA_OBJECT* rv) {
    const bool called = guarded(clips_env, [clips_env, rv](Builder* b) {
      reinterpret_cast<void (*)(void*, DATA_OBJECT*)>(reinterpret_cast<void (*)()>(b->original))(
          clips_env, rv);
    });
    if (!called) {
      rv->type = SYMBOL;
      rv->value = EnvFalseSymbol(clips_env);
    }
  }
};

namespace {

// CLIPS' allocator calls this when malloc fails; returning would hand CLIPS a null pointer (or,
// returning FALSE, retry forever), so the process ends here with a clear word instead of CLIPS'
// silent exit(1): exit code 1, the run failed (an agent's doing, not a bug of llsfsim's). The
// memory budget (max_memory_bytes) is meant to stop an agent long before.
int out_of_memory(void* clips_env, size_t size) {
  char text[320];
  const int n = std::snprintf(text, sizeof text,
                              "llsfsim: fatal: out of memory: CLIPS could not allocate %zu bytes "
                              "(this agent's environment holds %ld bytes); exiting with code 1: "
                              "the run fails (docs/clips.md, \"Budgets\")\n",
                              size, EnvMemUsed(clips_env));
  if (n > 0) (void)!::write(2, text, std::min(static_cast<std::size_t>(n), sizeof text - 1));
  std::_Exit(1);
}

}  // namespace

// ---- Environment -----------------------------------------------------------------------------

namespace {

// (fact-by-slot TEMPLATE SLOT VALUE): the first fact of TEMPLATE (in the order do-for-fact visits
// them) whose single-field SLOT is eq to VALUE, or FALSE. The same fact as
//   (do-for-fact ((?f TEMPLATE)) (eq ?f:SLOT VALUE) ?f)
// found by one C++ walk over the template's facts instead of evaluating the query's condition
// for each: a key look-up (a machine by name, an order by id) in a few dozen instructions.
void fact_by_slot(void* env, DATA_OBJECT* rv) {
  SetpType(rv, SYMBOL);
  SetpValue(rv, EnvFalseSymbol(env));
  DATA_OBJECT tmpl, slot, value;
  if (EnvArgTypeCheck(env, "fact-by-slot", 1, SYMBOL, &tmpl) == FALSE) return;
  if (EnvArgTypeCheck(env, "fact-by-slot", 2, SYMBOL, &slot) == FALSE) return;
  EnvRtnUnknown(env, 3, &value);
  auto* self = static_cast<Environment*>(GetEnvironmentContext(env));
  auto* t = static_cast<struct deftemplate*>(EnvFindDeftemplate(env, DOToString(tmpl)));
  if (t == nullptr || t->implied) {
    self->error("fact-by-slot", std::string("no deftemplate with slots named ") + DOToString(tmpl));
    return;
  }
  long pos = 0;
  const struct templateSlot* s = t->slotList;
  for (; s != nullptr && s->slotName != static_cast<SYMBOL_HN*>(GetValue(slot)); s = s->next) ++pos;
  if (s == nullptr || s->multislot) {
    self->error("fact-by-slot", std::string("deftemplate ") + DOToString(tmpl) +
                                    (s == nullptr ? " has no slot " : " has a multislot ") +
                                    DOToString(slot) +
                                    (s == nullptr ? "" : ": use a single-field slot"));
    return;
  }
  const int type = GetType(value);
  const void* v = GetValue(value);
  for (auto* f = static_cast<struct fact*>(EnvGetNextFactInTemplate(env, t, nullptr)); f != nullptr;
       f = static_cast<struct fact*>(EnvGetNextFactInTemplate(env, t, f))) {
    if (f->garbage) continue;
    const struct field& x = f->theProposition.theFields[pos];
    if (x.type == type && x.value == v) {
      SetpType(rv, FACT_ADDRESS);
      SetpValue(rv, f);
      return;
    }
  }
}

}  // namespace

Environment::Environment() {
  env_ = CreateEnvironment();
  if (env_ == nullptr) throw std::runtime_error("CLIPS: cannot create an environment");
  EnvAddRouterWithContext(env_, kRouterName, 40, &RouterAccess::query, &RouterAccess::print,
                          &RouterAccess::getc, &RouterAccess::ungetc, &RouterAccess::exit, this);
  SetEnvironmentContext(env_, this);
  EnvAddPeriodicFunction(env_, "llsf-budget", &Environment::periodic, 0);
  guard_ = std::make_unique<CallGuard>();
  guard_->install(env_);
  sizes_ = std::make_unique<SizeGuard>();
  sizes_->install(*this, env_);
  EnvSetOutOfMemoryFunction(env_, &out_of_memory);
  if (EnvDefineFunction2(env_, "fact-by-slot", 'u', clips_fn(&fact_by_slot), "fact_by_slot",
                         "33*") == FALSE)
    throw std::logic_error("CLIPS: cannot define function fact-by-slot");
}

std::int64_t Environment::memory_used() const { return EnvMemUsed(env_); }

bool Environment::enter_call(void* callee, bool generic) {
  periodic(env_);  // a call is a step of the work budget
  if (max_call_depth_ > 0 && call_depth_ >= max_call_depth_) {
    if (budget_hit_ == BudgetHit::kNone || budget_hit_ == BudgetHit::kDepth) {
      budget_hit_ = BudgetHit::kDepth;
      const char* name =
          generic ? EnvGetDefgenericName(env_, callee) : EnvGetDeffunctionName(env_, callee);
      budget_function_ = name != nullptr ? name : "";
    }
    SetEvaluationError(env_, TRUE);
    SetHaltExecution(env_, TRUE);
    return false;
  }
  ++call_depth_;
  return true;
}

void Environment::periodic(void* clips_env) {
  auto* self = static_cast<Environment*>(GetEnvironmentContext(clips_env));
  if (self == nullptr || self->max_steps_ <= 0) return;
  ++self->steps_;
  if (self->budget_hit_ == BudgetHit::kNone) {
    const std::int64_t memory = self->limits_.memory_bytes > 0 ? EnvMemUsed(clips_env) : 0;
    if (memory > self->limits_.memory_bytes) {
      self->budget_hit_ = BudgetHit::kMemory;
      self->budget_memory_ = memory;
    } else if (self->steps_ > self->max_steps_) {
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

void Environment::start_budget(std::int64_t max_steps, double max_wall_s, int max_call_depth) {
  steps_ = 0;
  max_call_depth_ = max_call_depth;
  call_depth_ = 0;
  budget_function_.clear();
  budget_memory_ = 0;
  max_steps_ = max_steps;
  max_wall_s_ = max_wall_s;
  budget_hit_ = BudgetHit::kNone;
  budget_start_ = std::chrono::steady_clock::now();
}

std::string Environment::executing_rule() const {
  struct defrule* rule = EngineData(env_)->ExecutingRule;
  const char* name = rule != nullptr ? EnvGetDefruleName(env_, rule) : nullptr;
  return name != nullptr ? std::string(name) : std::string();
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

namespace {

// The parser of a forbidden function: the call is a parse error naming the function.
struct expr* forbidden_parser(void* clips_env, struct expr* top, const char* /*logical_name*/) {
  const auto* self = static_cast<const Environment*>(GetEnvironmentContext(clips_env));
  const std::string name = ValueToString(ExpressionFunctionCallName(top));
  std::string text = "[LLSF2] " + name + ": " + self->forbidden_reason(name) + "\n";
  EnvPrintRouter(clips_env, WERROR, text.c_str());
  ReturnExpression(clips_env, top);
  return nullptr;
}

}  // namespace

void Environment::guard_concatenation(const std::string& name) {
  if (FindFunction(env_, name.c_str()) == nullptr)
    throw std::logic_error("CLIPS: no function " + name + " to guard");
  sizes_->guard(*this, env_, name.c_str(), SizeGuard::Kind::kConcat);
}

void Environment::forbid_function(const std::string& name, const std::string& message) {
  if (FindFunction(env_, name.c_str()) == nullptr) return;
  forbidden_[name] = message;
  define_function(name, "", [this, name](Args&) {
    error(name, forbidden_reason(name));
    return Value{};
  });
  if (AddFunctionParser(env_, name.c_str(), &forbidden_parser) == 0)
    throw std::logic_error("CLIPS: cannot forbid function " + name);
}

std::string Environment::forbidden_reason(std::string_view name) const {
  const auto it = forbidden_.find(name);
  return it != forbidden_.end() ? it->second : std::string("not available");
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

// The slot `slot` of deftemplate `name` as its declaration would read, with the constraints
// that limit it: "(slot c (type SYMBOL) (allowed-values RED GREEN))"; "" if there is no such
// slot.
std::string slot_declaration(void* env, const std::string& name, const std::string& slot) {
  void* t = EnvFindDeftemplate(env, name.c_str());
  if (t == nullptr || static_cast<struct deftemplate*>(t)->implied ||
      EnvDeftemplateSlotExistP(env, t, slot.c_str()) == FALSE)
    return {};
  const bool multi = EnvDeftemplateSlotMultiP(env, t, slot.c_str()) != FALSE;
  auto words = [env](const DATA_OBJECT& d) {
    std::string out;
    if (GetType(d) != MULTIFIELD) return out;
    for (const Value& v : to_value(env, d).items) {
      if (!out.empty()) out += ' ';
      out += v.to_string();
    }
    return out;
  };
  std::string out = std::string("(") + (multi ? "multislot " : "slot ") + slot;
  DATA_OBJECT d;
  EnvDeftemplateSlotTypes(env, t, slot.c_str(), &d);
  // Every type (no type facet) says nothing: left out.
  if (const std::string types = words(d); GetType(d) == MULTIFIELD && GetDOLength(d) < 8)
    out += " (type " + types + ")";
  EnvDeftemplateSlotAllowedValues(env, t, slot.c_str(), &d);
  if (GetType(d) == MULTIFIELD) out += " (allowed-values " + words(d) + ")";
  EnvDeftemplateSlotRange(env, t, slot.c_str(), &d);
  if (const std::string range = words(d); GetType(d) == MULTIFIELD && range != "-oo +oo")
    out += " (range " + range + ")";
  if (multi) {
    EnvDeftemplateSlotCardinality(env, t, slot.c_str(), &d);
    if (const std::string card = words(d); GetType(d) == MULTIFIELD && card != "0 +oo")
      out += " (cardinality " + card + ")";
  }
  return out + ")";
}

// A constraint error (CSTRNCHK1, RULECSTR1-3) made clearer: one found in a rule's conditions
// ("found in CE #2") is noticed when the whole rule has been read, so CLIPS' line is the rule's
// last: it becomes the line of that conditional element; and the message names what the slot
// allows, as its declaration reads ("; deftemplate todo has (slot order (type INTEGER))").
// `raw` is CLIPS' whole message (with the construct echoed up to the error), `forms` the
// source, read on first use.
void explain_constraint(void* env, LoadError& e, std::string_view raw, const std::string& text,
                        std::optional<std::vector<SourceNode>>& forms) {
  static const std::regex kCe(R"((?:CE|Pattern) #(\d+))");
  // "... for slot order.", "Variable ?x in CE #2 slot machine has ...", "... CE #1 slot n to ..."
  static const std::regex kSlot(R"((?:for|CE #\d+) slot ([^ .]+))");
  static const std::regex kRule(R"(\(in defrule ([^ )]+)\))");
  const bool constraint =
      e.message.starts_with("[CSTRNCHK1]") || e.message.starts_with("[RULECSTR1]") ||
      e.message.starts_with("[RULECSTR2]") || e.message.starts_with("[RULECSTR3]");
  std::smatch rule_m;
  if (!constraint || !std::regex_search(e.message, rule_m, kRule)) return;
  if (!forms) forms = read_source(text);
  const SourceNode* rule = find_defrule(*forms, rule_m[1].str());
  if (rule == nullptr) return;
  std::string relation;
  std::smatch m;
  if (std::regex_search(e.message, m, kCe)) {
    const std::vector<const SourceNode*> ces = rule_conditions(*rule);
    const int n = std::stoi(m[1].str());
    if (n < 1 || n > static_cast<int>(ces.size())) return;
    e.line = ces[static_cast<std::size_t>(n - 1)]->line;
    relation = std::string(ces[static_cast<std::size_t>(n - 1)]->head());
  } else {
    // In the actions: the template of the fact built, from the echo up to the error.
    const std::string_view echo = raw.substr(std::min(raw.size(), raw.find("ERROR:")));
    const std::size_t assert_at = echo.rfind("(assert (");
    std::size_t modify_at = echo.rfind("(modify ");
    if (const std::size_t d = echo.rfind("(duplicate "); d != std::string_view::npos)
      modify_at = modify_at == std::string_view::npos ? d : std::max(modify_at, d);
    if (assert_at != std::string_view::npos &&
        (modify_at == std::string_view::npos || assert_at > modify_at)) {
      std::string_view rest = echo.substr(assert_at + 9);
      relation = std::string(rest.substr(0, rest.find_first_of(" \t\n()")));
    } else if (modify_at != std::string_view::npos) {
      std::string_view rest = echo.substr(echo.find(' ', modify_at) + 1);
      rest = rest.substr(0, rest.find_first_of(" \t\n()"));
      relation = std::string(bound_relation(*rule, rest));
    }
  }
  if (relation.empty() || relation == "test" || !std::regex_search(e.message, m, kSlot)) return;
  const std::string declaration = slot_declaration(env, relation, m[1].str());
  if (declaration.empty()) return;
  std::string what = "; deftemplate " + relation + " has " + declaration;
  const std::size_t in_rule = e.message.rfind(" (in defrule ");
  std::size_t at = in_rule;
  if (at > 0 && e.message[at - 1] == '.') --at;  // "... for slot order." -> "... order; ..."
  e.message.replace(at, in_rule - at, what);
}

}  // namespace

std::vector<LoadError> Environment::load(const std::string& text) {
  ++code_version_;
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
  std::optional<std::vector<SourceNode>> forms;  // the source, read if an error needs it
  for (std::size_t i = 0; i < error_starts_.size(); ++i) {
    const std::size_t begin = error_starts_[i].first;
    const std::size_t end =
        i + 1 < error_starts_.size() ? error_starts_[i + 1].first : load_errors_.size();
    const std::string_view raw = std::string_view(load_errors_).substr(begin, end - begin);
    errors.push_back({error_starts_[i].second, compress_error(raw)});
    explain_constraint(env_, errors.back(), raw, text, forms);
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

std::vector<std::string> Environment::callable_names() const {
  std::vector<std::string> out;
  for (struct FunctionDefinition* f = GetFunctionList(env_); f != nullptr; f = f->next) {
    std::string name = ValueToString(f->callFunctionName);
    if (forbidden_.find(name) == forbidden_.end()) out.push_back(std::move(name));
  }
  for (void* f = EnvGetNextDeffunction(env_, nullptr); f; f = EnvGetNextDeffunction(env_, f))
    out.emplace_back(EnvGetDeffunctionName(env_, f));
  for (void* g = EnvGetNextDefgeneric(env_, nullptr); g; g = EnvGetNextDefgeneric(env_, g))
    out.emplace_back(EnvGetDefgenericName(env_, g));
  return out;
}

std::vector<std::string> Environment::template_slot_names(const std::string& name) const {
  std::vector<std::string> out;
  void* t = EnvFindDeftemplate(env_, name.c_str());
  if (t == nullptr || static_cast<struct deftemplate*>(t)->implied) return out;
  DATA_OBJECT names;
  EnvDeftemplateSlotNames(env_, t, &names);
  for (const auto& v : to_value(env_, names).items) out.push_back(v.text);
  return out;
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

Template Environment::implied_template(const std::string& name) {
  if (EnvFindDeftemplate(env_, name.c_str()) == nullptr) {
    CreateImpliedDeftemplate(env_, static_cast<SYMBOL_HN*>(EnvAddSymbol(env_, name.c_str())), TRUE);
  }
  Template t = find_template(name);
  if (!t.implied) throw std::logic_error("CLIPS: deftemplate " + name + " is not an ordered one");
  return t;
}

namespace {
// The value of slot i: values hold them (assert_fact) or point at them (nullptr: unset).
const Value* slot_value(std::span<const Value> values, std::size_t i) { return &values[i]; }
const Value* slot_value(std::span<const Value* const> values, std::size_t i) { return values[i]; }
}  // namespace

template <class Values>
FactHandle Environment::assert_slots(const Template& t, Values values) {
  auto* fact = static_cast<struct fact*>(EnvCreateFact(env_, t.ptr));
  if (fact == nullptr) throw std::logic_error("CLIPS: cannot create a fact of " + t.name);
  // The slots are written in place, as EnvPutFactSlot does, without its per-call look-up of the
  // slot by name (a symbol hash each) and without the temporary multifield of a DATA_OBJECT;
  // EnvAssignFactSlotDefaults then fills only the slots left unset. Same fact, fewer steps.
  struct field* fields = fact->theProposition.theFields;
  const std::size_t n = std::min(values.size(), t.slots.size());
  struct templateSlot* slot = static_cast<struct deftemplate*>(t.ptr)->slotList;
  for (std::size_t i = 0; i < n; ++i, slot = slot->next) {
    const Value* v = slot_value(values, i);
    if (v == nullptr || v->type == Value::Type::kVoid) continue;
    const bool multi = v->type == Value::Type::kMultifield;
    if (multi != (slot->multislot != 0))
      throw std::logic_error("CLIPS: cannot set slot " + t.slots[i] + " of " + t.name);
    if (fields[i].type == MULTIFIELD)
      ReturnMultifield(env_, static_cast<struct multifield*>(fields[i].value));
    if (multi) {
      fields[i].type = MULTIFIELD;
      fields[i].value = make_multifield(env_, v->items);
    } else {
      int type = 0;
      void* value = nullptr;
      atom(env_, *v, type, value);
      fields[i].type = static_cast<unsigned short>(type);
      fields[i].value = value;
    }
  }
  EnvAssignFactSlotDefaults(env_, fact);
  return assert_created(fact);
}

FactHandle Environment::assert_created(void* fact) {
  FactHandle h;
  void* asserted = EnvAssert(env_, fact);
  if (asserted != nullptr) {
    EnvIncrementFactCount(env_, asserted);
    h.fact_ = asserted;
  }
  return h;
}

FactHandle Environment::assert_fact(const Template& t, std::span<const Value> values) {
  if (!t.implied) return assert_slots(t, values);
  auto* fact = static_cast<struct fact*>(EnvCreateFact(env_, t.ptr));
  if (fact == nullptr) throw std::logic_error("CLIPS: cannot create a fact of " + t.name);
  struct field* fields = fact->theProposition.theFields;
  if (fields[0].type == MULTIFIELD)
    ReturnMultifield(env_, static_cast<struct multifield*>(fields[0].value));
  fields[0].type = MULTIFIELD;
  fields[0].value = make_multifield(env_, values);
  return assert_created(fact);
}

FactHandle Environment::assert_fact(const Template& t, std::span<const Value* const> values) {
  if (t.implied) throw std::logic_error("CLIPS: assert_fact by slot of ordered " + t.name);
  return assert_slots(t, values);
}

bool Environment::exists(const FactHandle& h) const {
  return h.fact_ != nullptr && EnvFactExistp(env_, h.fact_);
}

void Environment::retract(FactHandle& h) {
  if (h.fact_ == nullptr) return;
  if (EnvFactExistp(env_, h.fact_)) EnvRetract(env_, h.fact_);
  release(h);
}

int Environment::retract_all(const Template& t) {
  std::vector<void*> facts;
  for (void* f = EnvGetNextFactInTemplate(env_, t.ptr, nullptr); f != nullptr;
       f = EnvGetNextFactInTemplate(env_, t.ptr, f)) {
    facts.push_back(f);
  }
  for (void* f : facts) EnvRetract(env_, f);
  return static_cast<int>(facts.size());
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
  ++code_version_;
  DATA_OBJECT d;
  if (!EnvEval(env_, expression.c_str(), &d)) return {};
  return to_value(env_, d);
}

bool Environment::construct_texts(std::vector<std::string>& out) const {
  out.clear();
  bool complete = true;
  // Rules, functions and methods without a text could match or query anything; the others
  // without one are the system's (initial-fact, initial-object, the system classes' handlers).
  auto take = [&](const char* text, bool needed) {
    if (text != nullptr) {
      out.emplace_back(text);
    } else if (needed) {
      complete = false;
    }
  };
  void* const current = EnvGetCurrentModule(env_);
  for (void* m = EnvGetNextDefmodule(env_, nullptr); m != nullptr;
       m = EnvGetNextDefmodule(env_, m)) {
    EnvSetCurrentModule(env_, m);
    for (void* r = EnvGetNextDefrule(env_, nullptr); r; r = EnvGetNextDefrule(env_, r))
      take(EnvGetDefrulePPForm(env_, r), true);
    for (void* f = EnvGetNextDeffunction(env_, nullptr); f; f = EnvGetNextDeffunction(env_, f))
      take(EnvGetDeffunctionPPForm(env_, f), true);
    for (void* g = EnvGetNextDefgeneric(env_, nullptr); g; g = EnvGetNextDefgeneric(env_, g)) {
      for (long i = EnvGetNextDefmethod(env_, g, 0); i != 0; i = EnvGetNextDefmethod(env_, g, i))
        take(EnvGetDefmethodPPForm(env_, g, i), true);
    }
    for (void* d = EnvGetNextDeffacts(env_, nullptr); d; d = EnvGetNextDeffacts(env_, d))
      take(EnvGetDeffactsPPForm(env_, d), false);
    for (void* g = EnvGetNextDefglobal(env_, nullptr); g; g = EnvGetNextDefglobal(env_, g))
      take(EnvGetDefglobalPPForm(env_, g), false);
    for (void* c = EnvGetNextDefclass(env_, nullptr); c; c = EnvGetNextDefclass(env_, c)) {
      for (int i = EnvGetNextDefmessageHandler(env_, c, 0); i != 0;
           i = EnvGetNextDefmessageHandler(env_, c, i))
        take(EnvGetDefmessageHandlerPPForm(env_, c, i), false);
    }
    for (void* d = EnvGetNextDefinstances(env_, nullptr); d; d = EnvGetNextDefinstances(env_, d))
      take(EnvGetDefinstancesPPForm(env_, d), false);
  }
  EnvSetCurrentModule(env_, current);
  return complete;
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
