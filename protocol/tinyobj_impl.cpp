// Fuzz builds only (protocol/CMakeLists.txt): the implementation of Debian's
// header-only-capable tinyobjloader, compiled with instrumentation instead of
// linking the prebuilt libtinyobjloader_double.so.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
