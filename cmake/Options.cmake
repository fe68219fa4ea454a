# Compiler settings shared by every gilt target: call gilt_target_defaults(target).

function(gilt_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(GILT_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  # Keep fused multiply-add contraction off: the ray offset and the sphere test rely on
  # IEEE-exact products to stay watertight and scale-invariant.
  target_compile_options(${target} PRIVATE -ffp-contract=off)
endfunction()

# Sanitizers apply to every target, so the libraries are instrumented along with the tests.
if(GILT_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()

# Fuzzing (clang only): every target gets libFuzzer's coverage instrumentation and the sanitizers,
# so the loaders inside raytrace_core are what the fuzzer explores; the fuzz targets themselves
# link libFuzzer's main (tests/fuzz/CMakeLists.txt). Undefined behaviour aborts, so the fuzzer
# reports it as a crash.
if(GILT_FUZZ)
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
