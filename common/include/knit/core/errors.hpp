// The three kinds of failure (design/style.md, habit 4):
//  * bad input        -> InputError (file + JSON pointer + what to fix); main() exits with 2;
//  * broken invariant -> KNIT_ASSERT (debug builds);
//  * numerical outcome (no convergence, singular tangent, poor fit) -> a status in a report
//    struct, never an exception; main() decides the exit code (1).
// Library code never calls exit() or abort().
#pragma once

#include <cassert>
#include <stdexcept>
#include <string>

namespace knit {

/// Exit codes of the executables.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;   ///< a run that did not converge or could not finish
inline constexpr int kExitBadInput = 2;  ///< bad command line or input file

/// Bad user input. what() is one line: "<file>: <json pointer>: <message>".
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string pointer, const std::string& message)
      : std::runtime_error(compose(file, pointer, message)),
        file_(std::move(file)),
        pointer_(std::move(pointer)),
        message_(message) {}
  const std::string& file() const { return file_; }
  /// RFC 6901 JSON pointer of the offending field ("" for the whole document).
  const std::string& pointer() const { return pointer_; }
  const std::string& message() const { return message_; }

 private:
  static std::string compose(const std::string& f, const std::string& p, const std::string& m) {
    // A command-line option ("--max-output-size") names itself; "<input>" stands for a file
    // that has no name (session 37: "<input>: --max-output-size: ..." read as a file).
    if (f.empty() && p.rfind("-", 0) == 0) return p + ": " + m;
    std::string s = f.empty() ? std::string("<input>") : f;
    s += ": ";
    if (!p.empty()) s += p + ": ";
    return s + m;
  }
  std::string file_, pointer_, message_;
};

}  // namespace knit

#ifdef NDEBUG
#define KNIT_ASSERT(cond, msg) ((void)0)
#else
#define KNIT_ASSERT(cond, msg) assert((cond) && "knit: " msg)
#endif
