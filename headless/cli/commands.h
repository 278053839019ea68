// The bundlebake command line: `info`, `bake` (and later `importance`,
// `reference`, `compare`, `render`). Thin: parsing and printing only; the
// work is in engine/.
#pragma once

namespace bb::cli {
int run(int argc, char** argv);
}
