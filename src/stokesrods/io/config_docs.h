// The user guide of every configuration key, docs/config_keys.md (see config_docs.cc).
#pragma once

#include <string>

namespace stokesrods {

/// The page as Markdown. Throws std::logic_error when a key has no meaning or a meaning no key.
std::string ConfigKeysMarkdown();

}  // namespace stokesrods
