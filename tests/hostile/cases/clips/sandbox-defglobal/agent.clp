(defglobal ?*gone* = (remove "/tmp/llsf-x"))
