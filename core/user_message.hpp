// SPDX-License-Identifier: MIT
/// @file The user part of an error message, without the internal check locations of MLC_CHECK.
#pragma once

#include <string>

namespace mlc {

/// The user part of an error message: `what` without the internal check locations MLC_CHECK
/// appends (" [check `cond` in function, file.cpp:123]", anywhere in the text, as messages are
/// wrapped with prefixes). The locations removed, joined by "; ", go to `locations` if given.
/// For front ends that show the message to users (the Python module); the driver prints the whole
/// text.
std::string user_message(const std::string& what, std::string* locations = nullptr);

} // namespace mlc
