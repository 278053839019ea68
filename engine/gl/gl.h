// The one include for GL in the engine: the glad-generated GL 4.5 core loader.
// Functions are loaded through the context's getProcAddress (initializeGl).
#pragma once

#include <glad/gl.h>
