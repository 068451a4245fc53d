!> libinsitu for Fortran 2003 simulations: a thin module over the C API (insitu.h) through
!> iso_c_binding. Every function returns the C API's integer status (INSITU_OK, ...); nothing here
!> stops the simulation, and insitu_last_error() says what the most recent failure was.
!>
!>   use insitu
!>   type(insitu_instrument) :: instrument
!>   real(c_double), allocatable, target :: t(:, :, :)       ! t(nx, ny, nz), x fastest
!>   if (insitu_create_from_file("insitu.json", instrument) /= INSITU_OK) &
!>       print *, insitu_last_error()
!>   do step = 1, steps
!>       status = insitu_set_field(instrument, "temperature", t, ghosts=[1, 1, 1])
!>       status = insitu_execute(instrument, step, time)
!>   end do
!>   status = insitu_finalize(instrument)
!>   call insitu_destroy(instrument)
!>
!> Memory layout: Fortran arrays are column-major, so t(nx, ny, nz) has x varying fastest, which
!> is exactly libinsitu's x-fastest layout: dims = shape(t) = [nx, ny, nz], and sample t(i, j, k)
!> lies at origin + (i - 1 - ghost, j - 1 - ghost, k - 1 - ghost) * spacing. Nothing is copied
!> or transposed. Array sections that are not contiguous (t(::2, :, :)) are passed with their
!> strides, still without a copy.
!>
!> Standard: the interfaces are Fortran 2003 (iso_c_binding); the wrappers also use storage_size
!> (F2008) and is_contiguous (F2018; gfortran >= 9, ifx, flang).
!>
!> Lifetime: the library keeps a pointer to the array (zero-copy) until the next insitu_execute
!> returns, so give the array the TARGET attribute and do not deallocate it in between.
module insitu
    use, intrinsic :: iso_c_binding, only: c_associated, c_char, c_double, c_f_pointer, c_float, &
                                           c_int, c_int32_t, c_int64_t, c_intptr_t, c_loc, &
                                           c_null_char, c_null_ptr, c_ptr, c_size_t
    implicit none
    private

    !> Status codes, as in insitu.h.
    integer(c_int), parameter, public :: INSITU_OK = 0
    integer(c_int), parameter, public :: INSITU_NOT_SELECTED = 1  !< cadence skipped the step
    integer(c_int), parameter, public :: INSITU_DROPPED = 2       !< writer queue full, dropped
    integer(c_int), parameter, public :: INSITU_ERROR_INVALID_ARGUMENT = -1
    integer(c_int), parameter, public :: INSITU_ERROR_PARSE = -2
    integer(c_int), parameter, public :: INSITU_ERROR_COMPUTE = -3
    integer(c_int), parameter, public :: INSITU_ERROR_IO = -4
    integer(c_int), parameter, public :: INSITU_ERROR_STATE = -5
    integer(c_int), parameter, public :: INSITU_ERROR_UNKNOWN = -99

    !> Scalar types, as in insitu.h (the Fortran wrappers pick them from the array's type).
    integer(c_int), parameter :: INSITU_FLOAT32 = 3
    integer(c_int), parameter :: INSITU_FLOAT64 = 4

    !> The instrument a simulation holds. Null until created; insitu_destroy makes it null again.
    type, public :: insitu_instrument
        type(c_ptr) :: handle = c_null_ptr
    end type insitu_instrument

    public :: insitu_create_from_file, insitu_create_from_json, insitu_set_field, &
              insitu_execute, insitu_finalize, insitu_destroy, insitu_last_error, &
              insitu_status_name

    !> insitu_set_field(instrument, name, field, origin, spacing, ghosts) for 3D real arrays of
    !> either kind; dims come from shape(field).
    interface insitu_set_field
        module procedure set_field_double_3d
        module procedure set_field_float_3d
    end interface insitu_set_field

    !> insitu_execute(instrument, step, time) with a default (32-bit) or 64-bit step number.
    interface insitu_execute
        module procedure execute_step_int32
        module procedure execute_step_int64
    end interface insitu_execute

    ! The C functions, under private names so that the public names can be Fortran wrappers.
    interface
        function c_create_from_file(path, out) bind(C, name="insitu_create_from_file") &
            result(status)
            import :: c_char, c_int, c_ptr
            character(kind=c_char), dimension(*), intent(in) :: path
            type(c_ptr), intent(out) :: out
            integer(c_int) :: status
        end function c_create_from_file

        function c_create_from_json(json_text, out) bind(C, name="insitu_create_from_json") &
            result(status)
            import :: c_char, c_int, c_ptr
            character(kind=c_char), dimension(*), intent(in) :: json_text
            type(c_ptr), intent(out) :: out
            integer(c_int) :: status
        end function c_create_from_json

        function c_set_field_strided(instrument, name, data, scalar_type, dims, origin, spacing, &
                                     ghosts, strides) bind(C, name="insitu_set_field_strided") &
            result(status)
            import :: c_char, c_double, c_int, c_int64_t, c_ptr
            type(c_ptr), value :: instrument
            character(kind=c_char), dimension(*), intent(in) :: name
            type(c_ptr), value :: data
            integer(c_int), value :: scalar_type
            integer(c_int64_t), dimension(3), intent(in) :: dims
            real(c_double), dimension(3), intent(in) :: origin, spacing
            integer(c_int64_t), dimension(3), intent(in) :: ghosts
            type(c_ptr), value :: strides  ! NULL: contiguous
            integer(c_int) :: status
        end function c_set_field_strided

        function c_execute(instrument, step, time) bind(C, name="insitu_execute") result(status)
            import :: c_double, c_int, c_int64_t, c_ptr
            type(c_ptr), value :: instrument
            integer(c_int64_t), value :: step
            real(c_double), value :: time
            integer(c_int) :: status
        end function c_execute

        function c_finalize(instrument) bind(C, name="insitu_finalize") result(status)
            import :: c_int, c_ptr
            type(c_ptr), value :: instrument
            integer(c_int) :: status
        end function c_finalize

        subroutine c_destroy(instrument) bind(C, name="insitu_destroy")
            import :: c_ptr
            type(c_ptr), value :: instrument
        end subroutine c_destroy

        function c_last_error() bind(C, name="insitu_last_error") result(message)
            import :: c_ptr
            type(c_ptr) :: message
        end function c_last_error

        function c_status_name(status) bind(C, name="insitu_status_name") result(name)
            import :: c_int, c_ptr
            integer(c_int), value :: status
            type(c_ptr) :: name
        end function c_status_name

        function c_strlen(text) bind(C, name="strlen") result(length)
            import :: c_ptr, c_size_t
            type(c_ptr), value :: text
            integer(c_size_t) :: length
        end function c_strlen
    end interface

    ! Stands in for the data of a zero-size array, which has no element to take c_loc of; the
    ! C API then reports the zero dimension instead of a misleading "data is NULL".
    real(c_double), target, save :: no_samples(1) = 0.0_c_double

contains

    !> Creates an instrument from a JSON configuration file (see insitu/config.hpp).
    function insitu_create_from_file(path, instrument) result(status)
        character(len=*), intent(in) :: path
        type(insitu_instrument), intent(out) :: instrument
        integer(c_int) :: status
        status = c_create_from_file(to_c_string(path), instrument%handle)
    end function insitu_create_from_file

    !> Creates an instrument from JSON text.
    function insitu_create_from_json(json_text, instrument) result(status)
        character(len=*), intent(in) :: json_text
        type(insitu_instrument), intent(out) :: instrument
        integer(c_int) :: status
        status = c_create_from_json(to_c_string(json_text), instrument%handle)
    end function insitu_create_from_json

    !> Hands over (zero-copy) a real(c_double) field(nx, ny, nz) for the next insitu_execute.
    !> origin, spacing: world units (default 0 and 1); ghosts: layers skipped on each side of
    !> each axis (default 0).
    function set_field_double_3d(instrument, name, field, origin, spacing, ghosts) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_double), dimension(:, :, :), intent(in), target :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        type(c_ptr) :: data
        integer(c_int64_t), target :: strides(3)
        logical :: is_dense

        strides = 1_c_int64_t
        if (size(field) == 0) then
            data = c_loc(no_samples)
            is_dense = .true.
        else
            data = c_loc(field(1, 1, 1))
            ! is_contiguous is Fortran 2018 (gfortran >= 9); a dense array needs no strides.
            is_dense = is_contiguous(field)
            if (.not. is_dense) then
                strides = section_strides(data, c_loc(field(min(2, size(field, 1)), 1, 1)), &
                                          c_loc(field(1, min(2, size(field, 2)), 1)), &
                                          c_loc(field(1, 1, min(2, size(field, 3)))), &
                                          storage_size(field) / 8)
            end if
        end if
        status = set_field_any(instrument, name, data, INSITU_FLOAT64, shape(field), origin, &
                               spacing, ghosts, is_dense, strides)
    end function set_field_double_3d

    !> The same for real(c_float) fields.
    function set_field_float_3d(instrument, name, field, origin, spacing, ghosts) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_float), dimension(:, :, :), intent(in), target :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        type(c_ptr) :: data
        integer(c_int64_t), target :: strides(3)
        logical :: is_dense

        strides = 1_c_int64_t
        if (size(field) == 0) then
            data = c_loc(no_samples)
            is_dense = .true.
        else
            data = c_loc(field(1, 1, 1))
            ! is_contiguous is Fortran 2018 (gfortran >= 9); a dense array needs no strides.
            is_dense = is_contiguous(field)
            if (.not. is_dense) then
                strides = section_strides(data, c_loc(field(min(2, size(field, 1)), 1, 1)), &
                                          c_loc(field(1, min(2, size(field, 2)), 1)), &
                                          c_loc(field(1, 1, min(2, size(field, 3)))), &
                                          storage_size(field) / 8)
            end if
        end if
        status = set_field_any(instrument, name, data, INSITU_FLOAT32, shape(field), origin, &
                               spacing, ghosts, is_dense, strides)
    end function set_field_float_3d

    !> Computes the step, in the given time, with a default-kind step number.
    function execute_step_int32(instrument, step, time) result(status)
        type(insitu_instrument), intent(in) :: instrument
        integer(c_int32_t), intent(in) :: step
        real(c_double), intent(in) :: time
        integer(c_int) :: status
        status = c_execute(instrument%handle, int(step, c_int64_t), time)
    end function execute_step_int32

    function execute_step_int64(instrument, step, time) result(status)
        type(insitu_instrument), intent(in) :: instrument
        integer(c_int64_t), intent(in) :: step
        real(c_double), intent(in) :: time
        integer(c_int) :: status
        status = c_execute(instrument%handle, step, time)
    end function execute_step_int64

    !> Drains the writer; later executes return INSITU_ERROR_STATE.
    function insitu_finalize(instrument) result(status)
        type(insitu_instrument), intent(in) :: instrument
        integer(c_int) :: status
        status = c_finalize(instrument%handle)
    end function insitu_finalize

    !> Frees the instrument (finalizing first if needed) and nulls the handle. A null handle is
    !> fine, so destroying twice is harmless.
    subroutine insitu_destroy(instrument)
        type(insitu_instrument), intent(inout) :: instrument
        call c_destroy(instrument%handle)
        instrument%handle = c_null_ptr
    end subroutine insitu_destroy

    !> Message of the most recent failure on this thread ("" if none), as a Fortran string of
    !> exactly its length (no trailing blanks to trim).
    function insitu_last_error() result(message)
        character(len=:), allocatable :: message
        message = from_c_string(c_last_error())
    end function insitu_last_error

    !> Name of a status code, e.g. "INSITU_NOT_SELECTED".
    function insitu_status_name(status) result(name)
        integer(c_int), intent(in) :: status
        character(len=:), allocatable :: name
        name = from_c_string(c_status_name(status))
    end function insitu_status_name

    ! ---- helpers ----

    function set_field_any(instrument, name, data, scalar_type, shape_samples, origin, spacing, &
                           ghosts, is_dense, strides) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        type(c_ptr), intent(in) :: data
        integer(c_int), intent(in) :: scalar_type
        integer, dimension(3), intent(in) :: shape_samples
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        logical, intent(in) :: is_dense
        integer(c_int64_t), dimension(3), intent(in), target :: strides
        integer(c_int) :: status
        real(c_double) :: origin_world(3), spacing_world(3)
        integer(c_int64_t) :: ghost_layers(3)
        type(c_ptr) :: strides_pointer

        origin_world = 0.0_c_double
        spacing_world = 1.0_c_double
        ghost_layers = 0_c_int64_t
        if (present(origin)) origin_world = origin
        if (present(spacing)) spacing_world = spacing
        if (present(ghosts)) ghost_layers = int(ghosts, c_int64_t)
        strides_pointer = c_null_ptr
        if (.not. is_dense) strides_pointer = c_loc(strides)
        ! The C API checks everything else (null handle, unknown name, dims, ghosts, strides).
        status = c_set_field_strided(instrument%handle, to_c_string(name), data, scalar_type, &
                                     int(shape_samples, c_int64_t), origin_world, spacing_world, &
                                     ghost_layers, strides_pointer)
    end function set_field_any

    ! Strides in samples of an array section from the addresses of its first element and of the
    ! next element along x, y and z (the first element itself where an axis has one sample; its
    ! stride is then never used and is given as 1). A reversed section yields a negative stride,
    ! which the C API rejects with a message naming it.
    function section_strides(first, next_x, next_y, next_z, sample_bytes) result(strides)
        type(c_ptr), intent(in) :: first, next_x, next_y, next_z
        integer, intent(in) :: sample_bytes
        integer(c_int64_t) :: strides(3)
        strides(1) = stride_samples(first, next_x, sample_bytes)
        strides(2) = stride_samples(first, next_y, sample_bytes)
        strides(3) = stride_samples(first, next_z, sample_bytes)
    end function section_strides

    function stride_samples(first, next, sample_bytes) result(stride)
        type(c_ptr), intent(in) :: first, next
        integer, intent(in) :: sample_bytes
        integer(c_int64_t) :: stride
        integer(c_intptr_t) :: first_address, next_address
        first_address = transfer(first, first_address)
        next_address = transfer(next, next_address)
        stride = int((next_address - first_address) / sample_bytes, c_int64_t)
        if (stride == 0) stride = 1
    end function stride_samples

    ! Fortran strings carry a length instead of a terminator: add the NUL the C API expects.
    ! Trailing blanks are dropped, as fixed-length character variables are blank-padded.
    function to_c_string(text) result(c_text)
        character(len=*), intent(in) :: text
        character(kind=c_char, len=len_trim(text) + 1) :: c_text
        c_text = trim(text)//c_null_char
    end function to_c_string

    function from_c_string(c_text) result(text)
        type(c_ptr), intent(in) :: c_text
        character(len=:), allocatable :: text
        character(kind=c_char), dimension(:), pointer :: chars
        integer :: i, length

        if (.not. c_associated(c_text)) then
            text = ""
            return
        end if
        length = int(c_strlen(c_text))
        call c_f_pointer(c_text, chars, [length])
        allocate (character(len=length) :: text)
        do i = 1, length
            text(i:i) = chars(i)
        end do
    end function from_c_string

end module insitu
