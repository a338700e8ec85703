// SPDX-License-Identifier: MIT
// string.rep, string.find, string.match, string.gmatch and string.gsub for skills. string.rep
// checks the result's size first. The others: Lua 5.4 patterns (manual
// §6.4.1) matched by our own backtracking matcher, which charges its steps to the instruction
// budget. Lua's own matcher has no step limit: `("a"):rep(30000):find("a*a*a*a*a*b")` runs for
// hours inside one C call, where the count hook never fires.
//
// Costs (docs/skills.md, "Sandbox"): one instruction per matcher step (an item tried at a
// subject position, a character a quantifier or %b scans, a byte a back reference compares);
// plain searches one per candidate position plus the bytes compared there. Errors are raised at
// the calling skill's line (luaL_error level 1 from these C functions).
//
// Lua errors are longjmps: nothing here has a destructor.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "engine_impl.h"

namespace llsf::lua {

namespace {

constexpr std::ptrdiff_t kOpen = -1;      // capture started, not closed yet
constexpr std::ptrdiff_t kPosition = -2;  // position capture "()"
constexpr int kMaxDepth = 200;            // nested items (recursion) per match
constexpr int kMaxCaptures = 32;          // as many as Lua's own matcher allows
constexpr std::int64_t kChargeEvery = 1024;
constexpr const char* kSpecials = "^$*+?.([%-";

struct Capture {
  const char* start;
  std::ptrdiff_t len;
};

struct Matcher {
  lua_State* L;
  const char* fn;  // "string.find" etc., for budget messages
  const char* subject;
  const char* subject_end;
  const char* pattern_end;
  int depth;
  int level;             // captures in use
  std::int64_t pending;  // steps not yet charged
  Capture cap[kMaxCaptures];
};

void flush(Matcher& m) {
  if (m.pending == 0) return;
  const std::int64_t n = m.pending;
  m.pending = 0;
  lua_pushfstring(m.L, "%s: pattern matching", m.fn);
  // The message text lives on the stack until charge() returns or raises.
  charge(m.L, n, 1, lua_tostring(m.L, -1));
  lua_pop(m.L, 1);
}

void step(Matcher& m, std::int64_t n = 1) {
  m.pending += n;
  if (m.pending >= kChargeEvery) flush(m);
}

bool in_class(unsigned char c, unsigned char cls) {
  bool r = false;
  switch (std::tolower(cls)) {
    case 'a':
      r = std::isalpha(c) != 0;
      break;
    case 'c':
      r = std::iscntrl(c) != 0;
      break;
    case 'd':
      r = std::isdigit(c) != 0;
      break;
    case 'g':
      r = std::isgraph(c) != 0;
      break;
    case 'l':
      r = std::islower(c) != 0;
      break;
    case 'p':
      r = std::ispunct(c) != 0;
      break;
    case 's':
      r = std::isspace(c) != 0;
      break;
    case 'u':
      r = std::isupper(c) != 0;
      break;
    case 'w':
      r = std::isalnum(c) != 0;
      break;
    case 'x':
      r = std::isxdigit(c) != 0;
      break;
    case 'z':  // deprecated in Lua 5.2 but still understood by 5.4: the zero byte
      r = c == 0;
      break;
    default:
      return cls == c;  // %. for any non-alphanumeric '.': the character itself
  }
  return std::isupper(cls) != 0 ? !r : r;
}

// End (one past) of the single-character class starting at p.
const char* item_end(Matcher& m, const char* p) {
  if (*p == '%') {
    if (p + 1 >= m.pattern_end) luaL_error(m.L, "malformed pattern (ends with '%%')");
    return p + 2;
  }
  if (*p == '[') {
    const char* q = p + 1;
    if (q < m.pattern_end && *q == '^') ++q;
    for (bool first = true;; first = false) {
      if (q >= m.pattern_end) luaL_error(m.L, "malformed pattern (missing ']')");
      if (*q == ']' && !first) return q + 1;
      if (*q == '%') {
        ++q;
        if (q >= m.pattern_end) luaL_error(m.L, "malformed pattern (missing ']')");
      }
      ++q;
    }
  }
  return p + 1;
}

// c in the set [ ... ] from `open` (at '[') to `close` (at ']')?
bool in_set(unsigned char c, const char* open, const char* close) {
  const char* q = open + 1;
  bool negate = false;
  if (*q == '^') {
    negate = true;
    ++q;
  }
  bool found = false;
  while (q < close && !found) {
    const auto a = static_cast<unsigned char>(*q);
    if (a == '%' && q + 1 < close) {
      found = in_class(c, static_cast<unsigned char>(q[1]));
      q += 2;
    } else if (q + 2 < close && q[1] == '-') {
      found = a <= c && c <= static_cast<unsigned char>(q[2]);
      q += 3;
    } else {
      found = a == c;
      ++q;
    }
  }
  return found != negate;
}

// Does the subject character at s match the single-character class [p, ep)?
bool single(const Matcher& m, const char* s, const char* p, const char* ep) {
  if (s >= m.subject_end) return false;
  const auto c = static_cast<unsigned char>(*s);
  switch (*p) {
    case '.':
      return true;
    case '%':
      return in_class(c, static_cast<unsigned char>(p[1]));
    case '[':
      return in_set(c, p, ep - 1);
    default:
      return static_cast<unsigned char>(*p) == c;
  }
}

const char* match(Matcher& m, const char* s, const char* p);

const char* greedy(Matcher& m, const char* s, const char* p, const char* ep) {
  std::ptrdiff_t n = 0;
  while (single(m, s + n, p, ep)) {
    ++n;
    step(m);
  }
  for (; n >= 0; --n) {
    if (const char* r = match(m, s + n, ep + 1)) return r;
  }
  return nullptr;
}

const char* lazy(Matcher& m, const char* s, const char* p, const char* ep) {
  for (;;) {
    if (const char* r = match(m, s, ep + 1)) return r;
    if (!single(m, s, p, ep)) return nullptr;
    ++s;
  }
}

const char* open_capture(Matcher& m, const char* s, const char* p, std::ptrdiff_t kind) {
  if (m.level >= kMaxCaptures) luaL_error(m.L, "too many captures");
  m.cap[m.level] = {s, kind};
  ++m.level;
  const char* r = match(m, s, p);
  if (r == nullptr) --m.level;
  return r;
}

const char* close_capture(Matcher& m, const char* s, const char* p) {
  int open = m.level - 1;
  while (open >= 0 && m.cap[open].len != kOpen) --open;
  if (open < 0) luaL_error(m.L, "invalid pattern capture");
  m.cap[open].len = s - m.cap[open].start;
  const char* r = match(m, s, p);
  if (r == nullptr) m.cap[open].len = kOpen;
  return r;
}

// %bxy at p: a balanced run starting at s.
const char* balanced(Matcher& m, const char* s, const char* p) {
  if (m.pattern_end - p < 4) luaL_error(m.L, "malformed pattern (missing arguments to '%%b')");
  const char open = p[2];
  const char close = p[3];
  if (s >= m.subject_end || *s != open) return nullptr;
  int nesting = 1;
  for (const char* t = s + 1; t < m.subject_end; ++t) {
    step(m);
    if (*t == close) {
      if (--nesting == 0) return match(m, t + 1, p + 4);
    } else if (*t == open) {
      ++nesting;
    }
  }
  return nullptr;
}

const char* match(Matcher& m, const char* s, const char* p) {
  if (++m.depth > kMaxDepth)
    luaL_error(m.L, "pattern too complex (over %d nested items)", kMaxDepth);
  const char* result = nullptr;
  for (;;) {
    step(m);
    if (p >= m.pattern_end) {
      result = s;
      break;
    }
    if (*p == '(') {
      result = p + 1 < m.pattern_end && p[1] == ')' ? open_capture(m, s, p + 2, kPosition)
                                                    : open_capture(m, s, p + 1, kOpen);
      break;
    }
    if (*p == ')') {
      result = close_capture(m, s, p + 1);
      break;
    }
    if (*p == '$' && p + 1 == m.pattern_end) {
      result = s == m.subject_end ? s : nullptr;
      break;
    }
    if (*p == '%' && p + 1 < m.pattern_end) {
      if (p[1] == 'b') {
        result = balanced(m, s, p);
        break;
      }
      if (p[1] == 'f') {
        const char* set = p + 2;
        if (set >= m.pattern_end || *set != '[') {
          luaL_error(m.L, "missing '[' after '%%f' in pattern");
        }
        const char* ep = item_end(m, set);
        const auto before = static_cast<unsigned char>(s == m.subject ? '\0' : s[-1]);
        const auto here = static_cast<unsigned char>(s < m.subject_end ? *s : '\0');
        if (in_set(before, set, ep - 1) || !in_set(here, set, ep - 1)) break;
        p = ep;
        continue;
      }
      if (std::isdigit(static_cast<unsigned char>(p[1])) != 0) {
        const int i = p[1] - '1';
        if (i < 0 || i >= m.level || m.cap[i].len == kOpen) {
          luaL_error(m.L, "invalid capture index %%%d", i + 1);
        }
        const std::ptrdiff_t len = m.cap[i].len;
        if (len < 0 || m.subject_end - s < len) break;  // position captures never match
        step(m, len);
        if (std::memcmp(m.cap[i].start, s, static_cast<std::size_t>(len)) != 0) break;
        s += len;
        p += 2;
        continue;
      }
    }
    const char* ep = item_end(m, p);
    const char q = ep < m.pattern_end ? *ep : '\0';
    if (q == '?') {
      if (single(m, s, p, ep)) {
        if (const char* r = match(m, s + 1, ep + 1)) {
          result = r;
          break;
        }
      }
      p = ep + 1;
      continue;
    }
    if (q == '+') {
      result = single(m, s, p, ep) ? greedy(m, s + 1, p, ep) : nullptr;
      break;
    }
    if (q == '*') {
      result = greedy(m, s, p, ep);
      break;
    }
    if (q == '-') {
      result = lazy(m, s, p, ep);
      break;
    }
    if (!single(m, s, p, ep)) break;
    ++s;
    p = ep;
  }
  --m.depth;
  return result;
}

// Pushes capture i of the match [s, e) (capture 0 without captures: the whole match).
void push_capture(Matcher& m, int i, const char* s, const char* e) {
  if (i >= m.level) {
    if (i != 0) luaL_error(m.L, "invalid capture index %%%d", i + 1);
    lua_pushlstring(m.L, s, static_cast<std::size_t>(e - s));
    return;
  }
  const Capture& c = m.cap[i];
  if (c.len == kOpen) luaL_error(m.L, "unfinished capture");
  if (c.len == kPosition) {
    lua_pushinteger(m.L, static_cast<lua_Integer>(c.start - m.subject) + 1);
  } else {
    lua_pushlstring(m.L, c.start, static_cast<std::size_t>(c.len));
  }
}

// Pushes every capture (the whole match if there are none and `s` is given); returns the count.
int push_captures(Matcher& m, const char* s, const char* e) {
  const int n = m.level == 0 && s != nullptr ? 1 : m.level;
  luaL_checkstack(m.L, n, "too many captures");
  for (int i = 0; i < n; ++i) push_capture(m, i, s, e);
  return n;
}

void init(Matcher& m, lua_State* L, const char* fn, const char* s, std::size_t ls, const char* p,
          std::size_t lp) {
  m.L = L;
  m.fn = fn;
  m.subject = s;
  m.subject_end = s + ls;
  m.pattern_end = p + lp;
  m.depth = 0;
  m.level = 0;
  m.pending = 0;
}

// A 1-based (negative: from the end) start position as a 0-based offset clamped to [0, len];
// len + 1 if it lies beyond the end.
std::size_t start_offset(lua_Integer pos, std::size_t len) {
  const auto n = static_cast<lua_Integer>(len);
  if (pos > 0) return pos - 1 > n ? len + 1 : static_cast<std::size_t>(pos - 1);
  if (pos == 0 || pos < -n) return 0;
  return static_cast<std::size_t>(n + pos);
}

// Plain search of p (lp bytes) in s from offset `from`; charges its work.
const char* plain_find(lua_State* L, const char* s, std::size_t ls, std::size_t from, const char* p,
                       std::size_t lp) {
  if (lp == 0) return s + from;
  if (lp > ls - from) return nullptr;
  const char* last = s + (ls - lp);  // the last possible start
  const char* at = s + from;
  std::int64_t work = 0;
  const char* found = nullptr;
  while (at <= last) {
    const void* c = std::memchr(at, *p, static_cast<std::size_t>(last - at) + 1);
    if (c == nullptr) {
      work += (last - at) / 16 + 1;
      break;
    }
    const char* cand = static_cast<const char*>(c);
    work += (cand - at) / 16 + 1 + static_cast<std::int64_t>(lp);
    if (work >= kChargeEvery) {
      charge(L, work, 1, "string.find: plain search");
      work = 0;
    }
    if (std::memcmp(cand, p, lp) == 0) {
      found = cand;
      break;
    }
    at = cand + 1;
  }
  charge(L, work, 1, "string.find: plain search");
  return found;
}

bool has_specials(const char* p, std::size_t lp) {
  for (std::size_t i = 0; i < lp; ++i) {
    if (p[i] != '\0' && std::strchr(kSpecials, p[i]) != nullptr) return true;
  }
  return false;
}

int find_or_match(lua_State* L, bool find) {
  std::size_t ls = 0;
  std::size_t lp = 0;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  const std::size_t from = start_offset(luaL_optinteger(L, 3, 1), ls);
  if (from > ls) {
    luaL_pushfail(L);
    return 1;
  }
  const char* fn = find ? "string.find" : "string.match";
  if (find && (lua_toboolean(L, 4) != 0 || !has_specials(p, lp))) {
    if (const char* at = plain_find(L, s, ls, from, p, lp)) {
      lua_pushinteger(L, static_cast<lua_Integer>(at - s) + 1);
      lua_pushinteger(L, static_cast<lua_Integer>(at - s) + static_cast<lua_Integer>(lp));
      return 2;
    }
    luaL_pushfail(L);
    return 1;
  }
  Matcher m;
  const bool anchored = lp > 0 && *p == '^';
  if (anchored) {
    ++p;
    --lp;
  }
  init(m, L, fn, s, ls, p, lp);
  const char* at = s + from;
  for (;;) {
    m.level = 0;
    m.depth = 0;
    if (const char* e = match(m, at, p)) {
      flush(m);
      if (find) {
        lua_pushinteger(L, static_cast<lua_Integer>(at - s) + 1);
        lua_pushinteger(L, static_cast<lua_Integer>(e - s));
        return push_captures(m, nullptr, nullptr) + 2;
      }
      return push_captures(m, at, e);
    }
    if (anchored || at >= m.subject_end) break;
    ++at;
  }
  flush(m);
  luaL_pushfail(L);
  return 1;
}

int str_find(lua_State* L) { return find_or_match(L, true); }
int str_match(lua_State* L) { return find_or_match(L, false); }

// gmatch's iterator; upvalues: subject, pattern, next offset, end of the last match (-1: none).
int gmatch_next(lua_State* L) {
  std::size_t ls = 0;
  std::size_t lp = 0;
  const char* s = lua_tolstring(L, lua_upvalueindex(1), &ls);
  const char* p = lua_tolstring(L, lua_upvalueindex(2), &lp);
  auto pos = static_cast<std::size_t>(lua_tointeger(L, lua_upvalueindex(3)));
  const lua_Integer last = lua_tointeger(L, lua_upvalueindex(4));
  Matcher m;
  init(m, L, "string.gmatch", s, ls, p, lp);
  for (; pos <= ls; ++pos) {
    m.level = 0;
    m.depth = 0;
    const char* e = match(m, s + pos, p);
    if (e != nullptr && e - s != last) {
      flush(m);
      lua_pushinteger(L, static_cast<lua_Integer>(e - s));
      lua_copy(L, -1, lua_upvalueindex(3));
      lua_replace(L, lua_upvalueindex(4));
      return push_captures(m, s + pos, e);
    }
  }
  flush(m);
  lua_pushinteger(L, static_cast<lua_Integer>(ls) + 1);
  lua_replace(L, lua_upvalueindex(3));
  return 0;
}

int str_gmatch(lua_State* L) {
  std::size_t ls = 0;
  luaL_checklstring(L, 1, &ls);
  luaL_checkstring(L, 2);
  std::size_t from = start_offset(luaL_optinteger(L, 3, 1), ls);
  if (from > ls) from = ls + 1;
  lua_settop(L, 2);
  lua_pushinteger(L, static_cast<lua_Integer>(from));
  lua_pushinteger(L, -1);
  lua_pushcclosure(L, gmatch_next, 4);
  return 1;
}

// Appends the replacement for the match [s, e) to b (gsub's third argument at index 3).
void add_replacement(Matcher& m, luaL_Buffer& b, const char* s, const char* e, int repl_type) {
  lua_State* L = m.L;
  if (repl_type == LUA_TSTRING || repl_type == LUA_TNUMBER) {
    std::size_t lr = 0;
    const char* r = lua_tolstring(L, 3, &lr);
    for (std::size_t i = 0; i < lr; ++i) {
      if (r[i] != '%') {
        luaL_addchar(&b, r[i]);
        continue;
      }
      ++i;
      if (i < lr && r[i] == '%') {
        luaL_addchar(&b, '%');
      } else if (i < lr && std::isdigit(static_cast<unsigned char>(r[i])) != 0) {
        if (r[i] == '0') {
          luaL_addlstring(&b, s, static_cast<std::size_t>(e - s));
        } else {
          push_capture(m, r[i] - '1', s, e);
          luaL_tolstring(L, -1, nullptr);
          lua_remove(L, -2);
          luaL_addvalue(&b);
        }
      } else {
        luaL_error(L, "invalid use of '%%' in replacement string");
      }
    }
    return;
  }
  if (repl_type == LUA_TFUNCTION) {
    lua_pushvalue(L, 3);
    const int n = push_captures(m, s, e);
    lua_call(L, n, 1);
  } else {  // table
    push_capture(m, 0, s, e);
    lua_gettable(L, 3);
  }
  if (lua_toboolean(L, -1) == 0) {
    lua_pop(L, 1);
    luaL_addlstring(&b, s, static_cast<std::size_t>(e - s));
  } else if (lua_isstring(L, -1) == 0) {
    luaL_error(L, "invalid replacement value (a %s)", luaL_typename(L, -1));
  } else {
    luaL_addvalue(&b);
  }
}

int str_gsub(lua_State* L) {
  std::size_t ls = 0;
  std::size_t lp = 0;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  const int repl_type = lua_type(L, 3);
  const lua_Integer max_n = luaL_optinteger(L, 4, static_cast<lua_Integer>(ls) + 1);
  luaL_argexpected(L,
                   repl_type == LUA_TNUMBER || repl_type == LUA_TSTRING ||
                       repl_type == LUA_TFUNCTION || repl_type == LUA_TTABLE,
                   3, "string/function/table");
  const bool anchored = lp > 0 && *p == '^';
  if (anchored) {
    ++p;
    --lp;
  }
  Matcher m;
  init(m, L, "string.gsub", s, ls, p, lp);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  const char* src = s;
  const char* last = nullptr;
  lua_Integer n = 0;
  while (n < max_n) {
    m.level = 0;
    m.depth = 0;
    const char* e = match(m, src, p);
    if (e != nullptr && e != last) {
      ++n;
      flush(m);  // before a replacement function runs
      add_replacement(m, b, src, e, repl_type);
      src = last = e;
    } else if (src < m.subject_end) {
      luaL_addchar(&b, *src++);
    } else {
      break;
    }
    if (anchored) break;
  }
  flush(m);
  luaL_addlstring(&b, src, static_cast<std::size_t>(m.subject_end - src));
  luaL_pushresult(&b);
  lua_pushinteger(L, n);
  return 2;
}

// string.rep with the result's size checked before anything is allocated or copied: Lua's own
// loops n times even when the result is empty (string.rep("", 2^50)).
int str_rep(lua_State* L) {
  std::size_t l = 0;
  std::size_t lsep = 0;
  const char* s = luaL_checklstring(L, 1, &l);
  const lua_Integer n = luaL_checkinteger(L, 2);
  const char* sep = luaL_optlstring(L, 3, "", &lsep);
  if (n <= 0 || (l == 0 && lsep == 0)) {
    lua_pushliteral(L, "");
    return 1;
  }
  const auto limit = static_cast<std::uint64_t>(SkillEngine::Impl::of(L).config.memory_limit_bytes);
  const std::uint64_t unit = l + lsep;  // one copy of s and one separator
  const auto count = static_cast<std::uint64_t>(n);
  if (count > (limit + lsep) / unit) {
    char size[64];
    std::snprintf(
        size, sizeof size, "%.0f",
        static_cast<double>(count) * static_cast<double>(unit) - static_cast<double>(lsep));
    return luaL_error(L, "string.rep: result of %s bytes over the limit of %I bytes", size,
                      static_cast<LUA_INTEGER>(limit));
  }
  const std::size_t total = static_cast<std::size_t>(count * unit - lsep);
  luaL_Buffer b;
  char* out = luaL_buffinitsize(L, &b, total);
  // One copy of s and sep, then the filled part doubles (few memcpy calls for a short s).
  std::memcpy(out, s, l);
  std::size_t filled = l;
  if (count > 1) {
    std::memcpy(out + l, sep, lsep);
    filled += lsep;
  }
  while (filled < total) {
    const std::size_t n_copy = std::min(filled, total - filled);
    std::memcpy(out + filled, out, n_copy);
    filled += n_copy;
  }
  luaL_pushresultsize(&b, total);
  return 1;
}

}  // namespace

void push_pattern_functions(lua_State* L) {
  static const luaL_Reg fns[] = {{"rep", str_rep},       {"find", str_find}, {"match", str_match},
                                 {"gmatch", str_gmatch}, {"gsub", str_gsub}, {nullptr, nullptr}};
  luaL_newlib(L, fns);
}

}  // namespace llsf::lua
