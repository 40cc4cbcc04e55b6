// Errors as values inside the library; the CLI maps them to exit codes.
#pragma once
#include <string>
#include <utility>

namespace gibake {

// Documented process exit codes (README, DESIGN.md "Command line").
enum class ExitCode : int {
  Ok = 0,
  BadArguments = 1,
  IoFailure = 2,
  InvalidInput = 3,
  RuntimeFailure = 4,
  VerifyMismatch = 7,
};

// A failure: which file, where in it (e.g. "accessors[3]"), and what went wrong.
// Rendered as one line: "<file>: <where>: <what>" (the CLI prefixes "gibake: error: ").
class Status {
 public:
  Status() = default;
  static Status ok() { return Status(); }
  static Status error(ExitCode code, std::string file, std::string where, std::string what) {
    Status s;
    s.code_ = code;
    s.file_ = std::move(file);
    s.where_ = std::move(where);
    s.what_ = std::move(what);
    return s;
  }
  static Status invalid(std::string file, std::string where, std::string what) {
    return error(ExitCode::InvalidInput, std::move(file), std::move(where), std::move(what));
  }
  static Status io(std::string file, std::string what) {
    return error(ExitCode::IoFailure, std::move(file), "", std::move(what));
  }

  bool is_ok() const { return code_ == ExitCode::Ok; }
  explicit operator bool() const { return is_ok(); }
  ExitCode code() const { return code_; }
  const std::string& file() const { return file_; }
  const std::string& where() const { return where_; }
  const std::string& what() const { return what_; }

  // "<file>: <where>: <what>", omitting empty parts.
  std::string message() const {
    std::string m;
    auto add = [&m](const std::string& part) {
      if (part.empty()) return;
      if (!m.empty()) m += ": ";
      m += part;
    };
    add(file_);
    add(where_);
    add(what_);
    return m;
  }

 private:
  ExitCode code_ = ExitCode::Ok;
  std::string file_, where_, what_;
};

// Propagate a failed Status to the caller.
#define GIBAKE_TRY(expr)                 \
  do {                                   \
    ::gibake::Status _st = (expr);       \
    if (!_st.is_ok()) return _st;        \
  } while (0)

}  // namespace gibake
