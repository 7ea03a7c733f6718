// Helpers for the GoogleTest suite (included by *_test.cpp only, never by the library).
#pragma once
#include <initializer_list>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"

namespace ibl::test_util {

// Expects f() to throw an ibl::Error (of `kind`, when given) whose message contains every fragment.
template <typename F>
void expect_error(F&& f, std::initializer_list<std::string> fragments, std::optional<ErrorKind> kind = std::nullopt) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one containing \"" << (fragments.size() ? *fragments.begin() : "") << "\"";
  } catch (const Error& e) {
    if (kind) {
      EXPECT_EQ(static_cast<int>(e.kind()), static_cast<int>(*kind)) << e.what();
    }
    for (const auto& frag : fragments)
      EXPECT_NE(std::string(e.what()).find(frag), std::string::npos) << e.what() << " lacks " << frag;
  }
}
template <typename F>
void expect_error(F&& f, const std::string& fragment) {
  expect_error(std::forward<F>(f), {fragment});
}
template <typename F>
void expect_error(F&& f, ErrorKind kind, std::initializer_list<std::string> fragments) {
  expect_error(std::forward<F>(f), fragments, kind);
}

}  // namespace ibl::test_util
