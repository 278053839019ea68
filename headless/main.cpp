#include "headless/cli/commands.h"

int main(int argc, char** argv) { return bb::cli::run(argc, argv); }
