# Warnings for our own targets: gibake_warnings(<target>)
function(gibake_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
endfunction()
