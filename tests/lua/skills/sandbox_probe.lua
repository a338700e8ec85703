-- SPDX-License-Identifier: MIT
-- Test skill (plain execute()): fails naming every forbidden facility it can reach.
name               = "sandbox_probe"
documentation      = "checks the sandbox"

function execute()
   local reachable = {}
   -- (require is there: it loads only Lua helper modules of the skill directories)
   for _, n in ipairs{"io", "os", "load", "loadfile", "dofile", "loadstring",
                      "debug", "package", "collectgarbage", "coroutine", "_G"} do
      local ok, v = pcall(function() return _M[n] end)
      if ok and v ~= nil then reachable[#reachable + 1] = n end
   end
   if string.dump ~= nil then reachable[#reachable + 1] = "string.dump" end
   if getmetatable("") then reachable[#reachable + 1] = "the string metatable" end
   if ("%d"):format(7) ~= "7" then reachable[#reachable + 1] = "broken string methods" end
   local ok = pcall(setmetatable, {}, {__gc = function() end})
   if ok then reachable[#reachable + 1] = "__gc" end
   if #reachable > 0 then return S_FAILED, "reachable: " .. table.concat(reachable, ", ") end
   return S_FINAL
end
