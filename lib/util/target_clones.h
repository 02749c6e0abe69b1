#pragma once
// Function multiversioning for hot loops: on x86-64 with GCC or Clang, DGMM_TARGET_CLONES compiles
// a function twice, for the baseline and for x86-64-v3 (AVX2 + FMA), and the loader picks the
// clone the CPU supports (ifunc); helpers marked DGMM_ALWAYS_INLINE are compiled into each clone.
// Results may differ in the last bits between the clones (fused multiply-adds), never between runs
// on one machine. Elsewhere (and under AddressSanitizer) both expand to plain code.
#if defined __x86_64__ && (defined __GNUC__ || defined __clang__) && !defined __SANITIZE_ADDRESS__
#define DGMM_TARGET_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#define DGMM_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define DGMM_TARGET_CLONES
#define DGMM_ALWAYS_INLINE inline
#endif
