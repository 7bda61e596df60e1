// Provenance records (see knit/io/provenance.hpp).
#include "knit/io/provenance.hpp"

#include <unistd.h>

#include <ctime>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "knit/core/build_info.hpp"
#include "knit/io/hdf5.hpp"

namespace knit::io {

std::string utc_now_iso8601() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string process_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string out, arg;
  auto flush = [&] {
    if (!out.empty()) out += ' ';
    if (arg.empty() || arg.find_first_of(" \t'\"") != std::string::npos) {
      std::string q = "'";
      for (char c : arg) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
      out += q + "'";
    } else {
      out += arg;
    }
    arg.clear();
  };
  for (char c : raw) {
    if (c == '\0')
      flush();
    else
      arg += c;
  }
  if (!arg.empty()) flush();
  return out;
}

Provenance Provenance::current(const std::string& input) {
  Provenance p;
  p.version = knit::project_version();
  p.git_revision = knit::git_revision();
  p.date_utc = utc_now_iso8601();
  char host[256] = {0};
  if (gethostname(host, sizeof host - 1) == 0) p.host = host;
  p.command_line = process_command_line();
  p.input = input;
  return p;
}

std::string Provenance::to_json_string() const {
  nlohmann::ordered_json j;
  j["program"] = program;
  j["version"] = version;
  j["git_revision"] = git_revision;
  j["date_utc"] = date_utc;
  j["host"] = host;
  j["command_line"] = command_line;
  j["input"] = input;
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {
constexpr const char* kKeys[] = {"knit_program", "knit_version", "git_revision", "date_utc",
                                 "host",         "command_line", "input"};
std::string* field(Provenance& p, int i) {
  std::string* f[] = {&p.program, &p.version,      &p.git_revision, &p.date_utc,
                      &p.host,    &p.command_line, &p.input};
  return f[i];
}
}  // namespace

void write_provenance(H5Group& g, const Provenance& p, const std::string& obj_path) {
  Provenance copy = p;
  for (int i = 0; i < 7; ++i) g.set_attribute(obj_path, kKeys[i], *field(copy, i));
}

Provenance read_provenance(const H5Group& g, const std::string& obj_path) {
  Provenance p;
  p.program.clear();
  for (int i = 0; i < 7; ++i)
    if (g.has_attribute(obj_path, kKeys[i])) *field(p, i) = g.attribute_string(obj_path, kKeys[i]);
  return p;
}

}  // namespace knit::io
