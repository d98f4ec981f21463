// OpenGL 3.3 core entry points, linked from GLVND's libOpenGL (they dispatch to the current
// GLX or EGL context), so no loader is needed.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
