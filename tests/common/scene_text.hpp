// SPDX-License-Identifier: MIT
/// @file Helpers for tests that edit scene texts and check the parser's messages.
#pragma once

#include <string>

namespace mlc::test {

/// `s` with the first occurrence of `from` replaced by `to`; a missing `from` fails the test.
std::string replace(std::string s, const std::string& from, const std::string& to);

/// Parses `text` as a scene ("test.toml") and returns the InvalidInput message, or "" when
/// the scene is accepted.
std::string error_of(const std::string& text);

} // namespace mlc::test
