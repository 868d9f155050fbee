// What the tests of imported FE bodies share (test_fe_import, test_fe_scene,
// test_fe_interfaces, test_calculix): the message of an expected InputError and the check
// that it names what it should.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "core/errors.hpp"

namespace flexmbd::fetest {

/// The message of the InputError `f` throws (a test failure if it throws none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

/// Every one of `parts` occurs in `msg`.
inline void expectMentions(const std::string& msg, std::initializer_list<std::string> parts) {
  for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

}  // namespace flexmbd::fetest
