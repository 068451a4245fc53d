#include "insitu/error.hpp"

namespace insitu {

ErrorKind classify(const std::exception_ptr& error) {
    if (!error) return ErrorKind::none;
    try {
        std::rethrow_exception(error);
    } catch (const InvalidArgument&) {
        return ErrorKind::invalid_argument;
    } catch (const ParseError&) {
        return ErrorKind::parse;
    } catch (const ComputeError&) {
        return ErrorKind::compute;
    } catch (const IoError&) {
        return ErrorKind::io;
    } catch (const StateError&) {
        return ErrorKind::state;
    } catch (...) {
        return ErrorKind::unknown;
    }
}

}  // namespace insitu
