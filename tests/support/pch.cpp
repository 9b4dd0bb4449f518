// The translation unit that builds the tests' shared precompiled header (tests/CMakeLists.txt);
// every test executable reuses that header. It defines nothing.
