// Placeholder so the library has a source; removed when real sources land.
namespace gibake { int placeholder_io_placeholder_cpp() { return 0; } }
