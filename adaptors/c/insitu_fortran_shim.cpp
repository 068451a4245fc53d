// The one thing the Fortran module (insitu.f90) cannot say in Fortran: the address of an array
// element that has neither the TARGET nor the POINTER attribute (c_loc needs one of them).
// Fortran passes the element by reference to this function's assumed-type scalar dummy
// (type(*), Fortran 2018 18.3.6: interoperable with void*), which involves no array descriptor,
// so the function works for every Fortran compiler and is part of libinsitu itself: a
// simulation built with another compiler than libinsitu's compiles insitu.f90 and links
// -linsitu alone. Not in insitu.h: only the module calls it.
extern "C" const void* insitu_fortran_address(const void* sample);

extern "C" const void* insitu_fortran_address(const void* sample) {
    return sample;
}
