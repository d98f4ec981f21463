// Compiles the test suite's precompiled header (tests/CMakeLists.txt): GoogleTest and the whole
// public API, which every test includes, parsed once instead of once per test.
