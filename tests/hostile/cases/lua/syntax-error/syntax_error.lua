-- SPDX-License-Identifier: MIT
-- Hostile skill: a syntax error
name = "syntax_error"
documentation = "x"
function execute()
  if true
  return S_FINAL
end
