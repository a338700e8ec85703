-- SPDX-License-Identifier: MIT
-- Hostile skill: a navgraph file outside the cfg directories
name               = "navgraph_escape"
documentation      = "hostile input: reads a file outside the cfg directories"
function execute()
  local g = fawkes.load_yaml_navgraph("../../../etc/passwd")
  return S_FINAL
end
