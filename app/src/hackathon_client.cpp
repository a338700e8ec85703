// SPDX-License-Identifier: MIT
// The leaderboard's command-line client: one HTTP POST with Boost.Beast (hackathon_client.h).
#include "hackathon_client.h"

#include <fmt/format.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>

#include "llsf/app/cli.h"
#include "llsf/core/input_file.h"
#include "llsf/study/submission_store.h"

namespace llsf::app {

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

struct Url {
  std::string host;  ///< without brackets
  std::string port = "80";
  std::string base;   ///< path prefix without a trailing '/'
  std::string shown;  ///< scheme://host:port
};

/// http://HOST[:PORT][/PREFIX]; nullopt for anything else (https is not served).
std::optional<Url> parse_url(const std::string& text) {
  static const std::regex re(
      R"(^http://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+)(:([0-9]{1,5}))?(/.*)?$)");
  std::smatch m;
  if (!std::regex_match(text, m, re)) return std::nullopt;
  Url u;
  u.host = m[1].str();
  if (u.host.front() == '[') u.host = u.host.substr(1, u.host.size() - 2);
  if (m[3].matched) u.port = m[3].str();
  u.base = m[4].matched ? m[4].str() : "";
  while (!u.base.empty() && u.base.back() == '/') u.base.pop_back();
  u.shown = "http://" + m[1].str() + ":" + u.port;
  return u;
}

}  // namespace

std::shared_ptr<SubmitOptions> add_submit_options(CLI::App& app) {
  auto o = std::make_shared<SubmitOptions>();
  app.add_option("--submit", o->url,
                 "Instead of playing, send the skill file to the hackathon leaderboard at URL "
                 "(http://HOST:PORT/, from the organizer); needs --team");
  app.add_option("--team", o->team, "Your team's name on the leaderboard (with --submit)");
  return o;
}

int submit_skill(const SubmitOptions& o, const std::string& exercise, const std::string& skill_file,
                 std::ostream& out, std::ostream& err) {
  const char* who = "llsfsim exercise: ";
  const std::optional<Url> url = parse_url(o.url);
  if (!url) {
    err << who << "--submit: '" << o.url << "' is not an http://HOST:PORT/ address\n";
    return kExitBadInput;
  }
  if (o.team.empty()) {
    err << who << "--submit needs your team's name: --team NAME\n";
    return kExitBadInput;
  }
  if (exercise.empty()) {
    err << who
        << "name the exercise to submit for (llsfsim exercise NN --skill FILE --submit "
           "URL --team NAME)\n";
    return kExitBadInput;
  }
  if (skill_file.empty()) {
    err << who << "give the skill file to submit with --skill FILE\n";
    return kExitBadInput;
  }
  std::error_code ec;
  if (!fs::is_regular_file(skill_file, ec)) {
    err << who << "no such skill file: " << skill_file << core::near_path_hint(skill_file) << "\n";
    return kExitBadInput;
  }
  std::ifstream f(skill_file, std::ios::binary);
  const std::string content{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  if (!f.good() && !f.eof()) {
    err << who << "cannot read " << skill_file << "\n";
    return kExitBadInput;
  }
  if (!study::is_valid_utf8(content)) {
    err << who << skill_file << " is not UTF-8 text: save it as UTF-8 and submit again\n";
    return kExitBadInput;
  }
  // An exercise given as a directory is submitted by its name.
  std::string name = exercise;
  if (fs::is_directory(exercise, ec)) {
    name = fs::path(exercise).lexically_normal().filename().string();
    if (name.empty()) name = fs::path(exercise).lexically_normal().parent_path().filename();
  }
  const json body{{"team", o.team},
                  {"exercise", name},
                  {"file_name", fs::path(skill_file).filename().string()},
                  {"skill", content}};

  // One request with a 30 s limit on each step (asynchronous: tcp_stream's expiry applies only to
  // asynchronous operations).
  http::response<http::string_body> res;
  try {
    asio::io_context ioc;
    tcp::resolver resolver(ioc);
    beast::tcp_stream stream(ioc);
    http::request<http::string_body> req{http::verb::post, url->base + "/api/hackathon/submit", 11};
    req.set(http::field::host, url->host);
    req.set(http::field::content_type, "application/json");
    req.set(http::field::user_agent, "llsfsim");
    req.body() = body.dump();
    req.prepare_payload();
    beast::flat_buffer buffer;
    http::response_parser<http::string_body> parser;
    parser.body_limit(1 << 20);
    beast::error_code failed;
    const auto step_limit = std::chrono::seconds(30);
    stream.expires_after(step_limit);
    stream.async_connect(
        resolver.resolve(url->host, url->port), [&](beast::error_code cec, const tcp::endpoint&) {
          if (cec) {
            failed = cec;
            return;
          }
          stream.expires_after(step_limit);
          http::async_write(stream, req, [&](beast::error_code wec, std::size_t) {
            // A server that refuses the upload (413) answers before the body is all sent and
            // closes: the write fails, but its answer may be there to read.
            stream.expires_after(step_limit);
            http::async_read(stream, buffer, parser, [&, wec](beast::error_code rec, std::size_t) {
              failed = parser.is_done() ? beast::error_code() : (wec ? wec : rec);
            });
          });
        });
    ioc.run();
    if (failed) throw beast::system_error(failed);
    res = parser.release();
    beast::error_code ignored;
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
  } catch (const std::exception& e) {
    err << who << "cannot reach the leaderboard at " << url->shown << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  const json answer = json::parse(res.body(), nullptr, false);
  const int status = static_cast<int>(res.result_int());
  if (status != 202 || !answer.is_object()) {
    std::string message =
        answer.is_object() && answer.contains("error") && answer["error"].is_string()
            ? answer["error"].get<std::string>()
            : res.body().substr(0, 300);
    err << who << "the leaderboard refused the submission (HTTP " << status << "): " << message
        << "\n";
    return kExitBadInput;
  }
  const std::string ex = answer.value("exercise", name);
  out << fmt::format(
      "submitted {} for {} as team '{}': submission {}, queued ({} waiting before it)\n"
      "the board: {}{}/#{}\n",
      skill_file, ex, answer.value("team", o.team), answer.value("id", std::int64_t{0}),
      answer.value("queued_before", 0), url->shown, url->base, ex);
  return kExitOk;
}

}  // namespace llsf::app
