#pragma once
// Whether this test binary is built with a sanitizer (GCC's macros for -fsanitize=address and
// -fsanitize=thread). Real-time quality (how continuous a force is while threads race the wall
// clock) is reported under a sanitizer, not asserted: the instrumented code runs several times
// slower, and a late thread is the machine, not the code.
namespace spidar::test {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kUnderSanitizer = true;
#else
inline constexpr bool kUnderSanitizer = false;
#endif

}  // namespace spidar::test
