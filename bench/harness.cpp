// SPDX-License-Identifier: MIT
// Entry point of llsf-bench: `llsf-bench [NAME...]` runs the named benchmarks (all without names),
// `llsf-bench --list` lists them.
#include "harness.h"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>

namespace llsf::bench {

namespace {
struct Entry {
  std::string description;
  std::function<void()> fn;
};
std::map<std::string, Entry>& registry() {
  static std::map<std::string, Entry> r;
  return r;
}
}  // namespace

Registration::Registration(const char* name, const char* description, std::function<void()> fn) {
  registry()[name] = Entry{description, std::move(fn)};
}

void report(const std::string& bench, const std::string& metric, double value,
            const std::string& unit) {
  // 6 significant digits, as "%.6g" rounds them; dump() writes the shortest text of that value.
  char digits[32];
  std::snprintf(digits, sizeof digits, "%.6g", value);
  const nlohmann::ordered_json line = {{"bench", bench},
                                       {"metric", metric},
                                       {"value", std::strtod(digits, nullptr)},
                                       {"unit", unit}};
  std::printf("%s\n",
              line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
  std::fflush(stdout);
}

std::string tree() {
  const char* t = std::getenv("LLSF_BENCH_TREE");
  return t != nullptr && *t != '\0' ? std::string(t) : std::string(LLSF_SOURCE_DIR);
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median_of(int repeats, const std::function<double()>& body) {
  std::vector<double> v;
  for (int i = 0; i < repeats; ++i) v.push_back(body());
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace llsf::bench

int main(int argc, char** argv) {
  using llsf::bench::registry;
  if (argc > 1 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf(
        "usage: llsf-bench [--list] [NAME...]\n"
        "Runs the named benchmarks (all when none is named); prints one JSON object\n"
        "per result: {\"bench\", \"metric\", \"value\", \"unit\"}. Values are medians.\n");
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--list") == 0) {
    for (const auto& [name, e] : registry())
      std::printf("%-16s %s\n", name.c_str(), e.description.c_str());
    return 0;
  }
  std::vector<std::string> names;
  for (int i = 1; i < argc; ++i) {
    if (!registry().count(argv[i])) {
      std::fprintf(stderr, "llsf-bench: unknown benchmark '%s' (try --list)\n", argv[i]);
      return 2;
    }
    names.emplace_back(argv[i]);
  }
  if (names.empty())
    for (const auto& [name, e] : registry()) names.push_back(name);
  for (const auto& n : names) registry()[n].fn();
  return 0;
}
