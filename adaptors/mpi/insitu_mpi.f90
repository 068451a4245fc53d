!> libinsitu for MPI-parallel Fortran simulations: the `insitu` module's instrument, created over
!> the ranks of an MPI communicator (the C API of insitu_mpi.h through iso_c_binding).
!>
!>   use mpi
!>   use insitu
!>   use insitu_mpi
!>   type(insitu_instrument) :: instrument
!>   call MPI_Init(ierror)
!>   if (insitu_create_mpi("insitu.json", MPI_COMM_WORLD, instrument) /= INSITU_OK) &
!>       print *, insitu_last_error()
!>   do step = 1, steps                       ! every rank, with the same step and time
!>       status = insitu_add_block(instrument, "temperature", my_slab, origin=my_origin, &
!>                                 spacing=h, ghosts_low=[1, 1, 1])
!>       if (status == INSITU_OK) status = insitu_execute(instrument, step, time)
!>   end do
!>   status = insitu_finalize(instrument)
!>   call insitu_destroy(instrument)          ! before MPI_Finalize
!>   call MPI_Finalize(ierror)
!>
!> `comm` is the integer handle of the `mpi` module (and of mpif.h); with mpi_f08, pass
!> comm%MPI_VAL. Every other call is the `insitu` module's, made by every rank collectively
!> (insitu_mpi.h). Nothing here needs the MPI module itself, so this file compiles with any
!> Fortran compiler; the C side (libinsitu_mpi) must be built with the simulation's MPI.
module insitu_mpi
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char, c_ptr
    use insitu, only: insitu_instrument
    implicit none
    private

    public :: insitu_create_mpi

    interface
        function c_create_mpi_f(path, comm, out) bind(C, name="insitu_create_mpi_f") &
            result(status)
            import :: c_char, c_int, c_ptr
            character(kind=c_char), dimension(*), intent(in) :: path
            integer(c_int), value :: comm  ! MPI_Fint
            type(c_ptr), intent(out) :: out
            integer(c_int) :: status
        end function c_create_mpi_f
    end interface

contains

    !> Creates an instrument from a JSON configuration file, distributed over the ranks of `comm`
    !> (collective). Status codes as insitu_create_from_file's (insitu_mpi.h).
    function insitu_create_mpi(path, comm, instrument) result(status)
        character(len=*), intent(in) :: path
        integer, intent(in) :: comm
        type(insitu_instrument), intent(out) :: instrument
        integer(c_int) :: status
        status = c_create_mpi_f(to_c_string(path), int(comm, c_int), instrument%handle)
    end function insitu_create_mpi

    ! As the `insitu` module's: the NUL the C API expects, trailing blanks dropped.
    function to_c_string(text) result(c_text)
        character(len=*), intent(in) :: text
        character(kind=c_char, len=len_trim(text) + 1) :: c_text
        c_text = trim(text)//c_null_char
    end function to_c_string

end module insitu_mpi
