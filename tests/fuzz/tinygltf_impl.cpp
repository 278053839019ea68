// tinygltf's implementation compiled with the fuzzer's instrumentation (the
// engine links Debian's libtinygltf.so, which is not instrumented). stb_image
// and stb_image_write come from Debian's libstb.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
