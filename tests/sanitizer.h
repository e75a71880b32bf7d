#pragma once

// Whether the tests (and so glint, built with the same flags) run under the address sanitizer.
// Its shadow memory reserves terabytes of address space and its quarantine keeps freed blocks, so
// address-space caps and peak-memory figures say nothing about glint then.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif
