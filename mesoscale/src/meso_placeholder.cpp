// Placeholder so that the library target exists before its first translation unit lands.
namespace knit::meso {}
