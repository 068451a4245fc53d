!> libinsitu for Fortran simulations: a thin module over the C API (insitu.h) through
!> iso_c_binding. Every function returns the C API's integer status (INSITU_OK, ...); nothing here
!> stops the simulation, and insitu_last_error() says what the most recent failure was.
!>
!>   use insitu
!>   type(insitu_instrument) :: instrument
!>   real(c_double), allocatable :: t(:, :, :)       ! t(nx, ny, nz), x fastest; no TARGET needed
!>   if (insitu_create_from_file("insitu.json", instrument) /= INSITU_OK) &
!>       print *, insitu_last_error()
!>   do step = 1, steps
!>       call simulate(t)
!>       status = INSITU_OK
!>       if (insitu_selects(instrument, step)) &             ! only steps the cadence keeps
!>           status = insitu_set_field(instrument, "temperature", t, ghosts=[1, 1, 1])
!>       if (status == INSITU_OK) status = insitu_execute(instrument, step, time)
!>   end do
!>   status = insitu_finalize(instrument)
!>   call insitu_destroy(instrument)
!>
!> Memory layout: Fortran arrays are column-major, so t(nx, ny, nz) has x varying fastest, which
!> is exactly libinsitu's x-fastest layout: dims = shape(t) = [nx, ny, nz], and sample t(i, j, k)
!> lies at origin + (i - 1 - ghost, j - 1 - ghost, k - 1 - ghost) * spacing. Nothing is copied
!> or transposed. Array sections that are not contiguous (t(2:n - 1, :, ::2)) are passed with
!> their strides, still without a copy: the field dummies are assumed-shape without CONTIGUOUS,
!> which compilers pass as a descriptor of the actual argument's own storage, and ASYNCHRONOUS,
!> for which Fortran 2018 (15.5.2.4) rules the copy out when the actual is ASYNCHRONOUS too. A
!> section with a vector subscript (t([1, 3], :, :)), which would need a copy, may not be passed
!> to an ASYNCHRONOUS dummy at all; gfortran refuses it at compile time.
!>
!> Types: real(c_double), real(c_float), integer(c_int16_t) (signed, INSITU_INT16; with
!> unsigned=.true. its bits are read as INSITU_UINT16, 0 to 65535), integer(c_int8_t) (always read
!> as unsigned bytes, INSITU_UINT8, 0 to 255: libinsitu has no signed 8-bit type and Fortran no
!> unsigned one). Arrays are 3D.
!>
!> insitu_set_field hands over one node-centred array per field, replacing any earlier one.
!> insitu_add_block(instrument, name, field, origin, spacing, ghosts_low, ghosts_high, centering)
!> appends one block: several blocks of a field (the tiles a rank owns) are joined on their common
!> grid, and centering=INSITU_CELL marks cell-centred data (origin = low corner of the first
!> interior cell). Cell-centred data goes through insitu_add_block, once per field and step.
!>
!> Lifetime (the one rule): the library keeps the array's address, not a copy, and reads the
!> samples during the next insitu_execute. Until that returns, the array must stay allocated and
!> in place (no deallocate, move_alloc, or assignment that reallocates it to another shape), and
!> its values should stay as they were handed over. Hand over a variable (an array or a section
!> of one), never an expression such as real(t, c_float) or t * 2, whose value lives in a
!> temporary that is gone when insitu_set_field returns: copy it into an array of your own. No
!> TARGET attribute is needed. This is the contract of the nonblocking calls of MPI's mpi_f08
!> module (MPI_Isend ... MPI_Wait), with insitu_set_field or insitu_add_block as the start and
!> insitu_execute as the end, and it has the same fine print: standard Fortran lets a compiler
!> assume that a call that does not name a non-TARGET array (insitu_execute) does not read it,
!> and so move a write to the array across that call, e.g. the next time step's before it.
!> Optimizers treat memory whose address was passed to a call (insitu_set_field) as reachable by
!> later calls, so this is a licence taken in theory only; declaring the array ASYNCHRONOUS in
!> the simulation (optional, and free) withdraws it, as for MPI buffers.
!>
!> Why no TARGET: c_loc needs TARGET or POINTER, so the module instead passes the array's first
!> element, and its neighbours along x, y and z, by reference to insitu_fortran_address, a C
!> function that returns its argument (adaptors/c/insitu_fortran_shim.cpp), through an
!> assumed-type scalar dummy, which is a plain void* (Fortran 2018 18.3.6); the strides of a
!> section are the distances between those addresses. Assumed-rank dummies with a C descriptor
!> (ISO_Fortran_binding.h) would do the same in one procedure for every type, but the layout of
!> that descriptor is each compiler's own, so their C side would have to be built once per
!> Fortran compiler; a void* is the same for all, and the shim lives in libinsitu itself.
!>
!> Standard: Fortran 2018 (type(*), is_contiguous; gfortran >= 9). With another compiler than the
!> one libinsitu was built with, compile this file (installed as share/insitu/fortran/insitu.f90)
!> with the simulation and link -linsitu alone.
module insitu
    use, intrinsic :: iso_c_binding, only: c_associated, c_char, c_double, c_f_pointer, c_float, &
                                           c_int, c_int16_t, c_int32_t, c_int64_t, c_int8_t, &
                                           c_intptr_t, c_loc, c_null_char, c_null_ptr, c_ptr, &
                                           c_size_t
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

    !> Centring of a block's samples (insitu_add_block's `centering`), as in insitu.h.
    integer(c_int), parameter, public :: INSITU_NODE = 0
    integer(c_int), parameter, public :: INSITU_CELL = 1

    !> Scalar types, as in insitu.h (the wrappers pick them from the array's type and kind).
    integer(c_int), parameter :: INSITU_UINT8 = 0
    integer(c_int), parameter :: INSITU_UINT16 = 1
    integer(c_int), parameter :: INSITU_INT16 = 2
    integer(c_int), parameter :: INSITU_FLOAT32 = 3
    integer(c_int), parameter :: INSITU_FLOAT64 = 4

    !> The instrument a simulation holds. Null until created; insitu_destroy makes it null again.
    type, public :: insitu_instrument
        type(c_ptr) :: handle = c_null_ptr
    end type insitu_instrument

    ! Where an array's samples are: the address of its first element, its extents and, unless it
    ! is contiguous, the distance between neighbours along x, y, z in samples.
    type :: sample_layout
        type(c_ptr) :: data = c_null_ptr
        integer(c_int64_t) :: dims(3) = 0
        logical :: contiguous = .true.
        integer(c_int64_t) :: strides(3) = 1
    end type sample_layout

    public :: insitu_create_from_file, insitu_create_from_json, insitu_set_field, &
              insitu_add_block, insitu_selects, insitu_execute, insitu_finalize, insitu_destroy, &
              insitu_last_error, insitu_status_name

    !> insitu_set_field(instrument, name, field, origin, spacing, ghosts) for 3D arrays of the
    !> types above (int16 ones also take `unsigned`); dims come from shape(field). Replaces the
    !> field's earlier blocks with this one, node-centred.
    interface insitu_set_field
        module procedure set_field_real64
        module procedure set_field_real32
        module procedure set_field_int16
        module procedure set_field_int8
    end interface insitu_set_field

    !> insitu_add_block(instrument, name, field, origin, spacing, ghosts_low, ghosts_high,
    !> centering) (int16 arrays also take `unsigned`): appends one block of the field (see the
    !> module's comment).
    interface insitu_add_block
        module procedure add_block_real64
        module procedure add_block_real32
        module procedure add_block_int16
        module procedure add_block_int8
    end interface insitu_add_block

    !> insitu_selects(instrument, step): .true. when insitu_execute would compute the step, with a
    !> default (32-bit) or 64-bit step number.
    interface insitu_selects
        module procedure selects_step_int32
        module procedure selects_step_int64
    end interface insitu_selects

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

        function c_add_block(instrument, name, data, scalar_type, dims, origin, spacing, &
                             ghosts_low, ghosts_high, strides, centering) &
            bind(C, name="insitu_add_block") result(status)
            import :: c_char, c_double, c_int, c_int64_t, c_ptr
            type(c_ptr), value :: instrument
            character(kind=c_char), dimension(*), intent(in) :: name
            type(c_ptr), value :: data
            integer(c_int), value :: scalar_type
            integer(c_int64_t), dimension(3), intent(in) :: dims
            real(c_double), dimension(3), intent(in) :: origin, spacing
            integer(c_int64_t), dimension(3), intent(in) :: ghosts_low, ghosts_high
            type(c_ptr), value :: strides  ! NULL: contiguous
            integer(c_int), value :: centering
            integer(c_int) :: status
        end function c_add_block

        function c_selects(instrument, step) bind(C, name="insitu_selects") result(status)
            import :: c_int, c_int64_t, c_ptr
            type(c_ptr), value :: instrument
            integer(c_int64_t), value :: step
            integer(c_int) :: status
        end function c_selects

        subroutine c_name_next_call(entry_name) bind(C, name="insitu_name_next_call")
            import :: c_char
            character(kind=c_char), dimension(*), intent(in) :: entry_name
        end subroutine c_name_next_call

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

        ! The address of `sample`, which Fortran passes by reference to an assumed-type scalar
        ! (a void* in C): c_loc without the TARGET attribute (see the module's comment).
        function c_address(sample) bind(C, name="insitu_fortran_address") result(address)
            import :: c_ptr
            type(*), intent(in) :: sample
            type(c_ptr) :: address
        end function c_address

        function c_strlen(text) bind(C, name="strlen") result(length)
            import :: c_ptr, c_size_t
            type(c_ptr), value :: text
            integer(c_size_t) :: length
        end function c_strlen
    end interface

    ! Stands in for the data of a zero-size array, which has no element to take the address of;
    ! the C API then reports the zero dimension instead of a misleading "data is NULL".
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

    ! ---- insitu_set_field: one specific procedure per type; origin, spacing: world units
    ! (default 0 and 1); ghosts: layers skipped on each side of each axis (default 0).

    function set_field_real64(instrument, name, field, origin, spacing, ghosts) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_double), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        status = set_field_layout(instrument, name, layout_real64(field), INSITU_FLOAT64, &
                                  origin, spacing, ghosts)
    end function set_field_real64

    function set_field_real32(instrument, name, field, origin, spacing, ghosts) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_float), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        status = set_field_layout(instrument, name, layout_real32(field), INSITU_FLOAT32, &
                                  origin, spacing, ghosts)
    end function set_field_real32

    !> unsigned=.true.: the samples' bits are read as unsigned (INSITU_UINT16).
    function set_field_int16(instrument, name, field, origin, spacing, ghosts, unsigned) &
        result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        integer(c_int16_t), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        logical, intent(in), optional :: unsigned
        integer(c_int) :: status
        status = set_field_layout(instrument, name, layout_int16(field), int16_type(unsigned), &
                                  origin, spacing, ghosts)
    end function set_field_int16

    !> Bytes are read as unsigned (INSITU_UINT8).
    function set_field_int8(instrument, name, field, origin, spacing, ghosts) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        integer(c_int8_t), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        status = set_field_layout(instrument, name, layout_int8(field), INSITU_UINT8, origin, &
                                  spacing, ghosts)
    end function set_field_int8

    ! ---- insitu_add_block: as insitu_set_field, with ghosts_low and ghosts_high (layers skipped
    ! on the low and high side of each axis; default 0, ghosts_high defaults to ghosts_low) and
    ! centering (INSITU_NODE, the default, or INSITU_CELL).

    function add_block_real64(instrument, name, field, origin, spacing, ghosts_low, ghosts_high, &
                              centering) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_double), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts_low, ghosts_high
        integer(c_int), intent(in), optional :: centering
        integer(c_int) :: status
        status = add_block_layout(instrument, name, layout_real64(field), INSITU_FLOAT64, &
                                  origin, spacing, ghosts_low, ghosts_high, centering)
    end function add_block_real64

    function add_block_real32(instrument, name, field, origin, spacing, ghosts_low, ghosts_high, &
                              centering) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        real(c_float), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts_low, ghosts_high
        integer(c_int), intent(in), optional :: centering
        integer(c_int) :: status
        status = add_block_layout(instrument, name, layout_real32(field), INSITU_FLOAT32, &
                                  origin, spacing, ghosts_low, ghosts_high, centering)
    end function add_block_real32

    function add_block_int16(instrument, name, field, origin, spacing, ghosts_low, ghosts_high, &
                             centering, unsigned) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        integer(c_int16_t), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts_low, ghosts_high
        integer(c_int), intent(in), optional :: centering
        logical, intent(in), optional :: unsigned
        integer(c_int) :: status
        status = add_block_layout(instrument, name, layout_int16(field), int16_type(unsigned), &
                                  origin, spacing, ghosts_low, ghosts_high, centering)
    end function add_block_int16

    function add_block_int8(instrument, name, field, origin, spacing, ghosts_low, ghosts_high, &
                            centering) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        integer(c_int8_t), dimension(:, :, :), intent(in), asynchronous :: field
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts_low, ghosts_high
        integer(c_int), intent(in), optional :: centering
        integer(c_int) :: status
        status = add_block_layout(instrument, name, layout_int8(field), INSITU_UINT8, origin, &
                                  spacing, ghosts_low, ghosts_high, centering)
    end function add_block_int8

    !> Whether insitu_execute would compute this step: the cadence selects it and the archive
    !> does not hold it yet. Fields need only be set when it is .true.; insitu_execute is still
    !> called every step. .false. also on an error (e.g. after insitu_finalize), which the next
    !> insitu_execute then reports.
    function selects_step_int32(instrument, step) result(selected)
        type(insitu_instrument), intent(in) :: instrument
        integer(c_int32_t), intent(in) :: step
        logical :: selected
        selected = c_selects(instrument%handle, int(step, c_int64_t)) == INSITU_OK
    end function selects_step_int32

    function selects_step_int64(instrument, step) result(selected)
        type(insitu_instrument), intent(in) :: instrument
        integer(c_int64_t), intent(in) :: step
        logical :: selected
        selected = c_selects(instrument%handle, step) == INSITU_OK
    end function selects_step_int64

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

    ! The C insitu_set_field_strided, reporting failures as the Fortran insitu_set_field (the
    ! other wrappers call the C function of their own name, which needs no renaming). The C API
    ! checks everything else (null handle, unknown name, dims, ghosts, strides).
    function set_field_layout(instrument, name, layout, scalar_type, origin, spacing, ghosts) &
        result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        type(sample_layout), intent(in) :: layout
        integer(c_int), intent(in) :: scalar_type
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int) :: status
        integer(c_int64_t), target :: strides(3)

        strides = layout%strides
        call c_name_next_call(to_c_string("insitu_set_field"))
        status = c_set_field_strided(instrument%handle, to_c_string(name), layout%data, &
                                     scalar_type, layout%dims, world_origin(origin), &
                                     world_spacing(spacing), layer_counts(ghosts), &
                                     strides_pointer(layout, strides))
    end function set_field_layout

    function add_block_layout(instrument, name, layout, scalar_type, origin, spacing, &
                              ghosts_low, ghosts_high, centering) result(status)
        type(insitu_instrument), intent(in) :: instrument
        character(len=*), intent(in) :: name
        type(sample_layout), intent(in) :: layout
        integer(c_int), intent(in) :: scalar_type
        real(c_double), dimension(3), intent(in), optional :: origin, spacing
        integer, dimension(3), intent(in), optional :: ghosts_low, ghosts_high
        integer(c_int), intent(in), optional :: centering
        integer(c_int) :: status
        integer(c_int64_t), target :: strides(3)
        integer(c_int64_t) :: low_layers(3), high_layers(3)
        integer(c_int) :: centering_code

        strides = layout%strides
        low_layers = layer_counts(ghosts_low)
        high_layers = low_layers
        if (present(ghosts_high)) high_layers = layer_counts(ghosts_high)
        centering_code = INSITU_NODE
        if (present(centering)) centering_code = centering
        status = c_add_block(instrument%handle, to_c_string(name), layout%data, scalar_type, &
                             layout%dims, world_origin(origin), world_spacing(spacing), &
                             low_layers, high_layers, strides_pointer(layout, strides), &
                             centering_code)
    end function add_block_layout

    ! One layout function per type: Fortran has no generic element access to an array whose
    ! type is not known. Each passes its first element and that element's neighbours along x, y
    ! and z (the first element itself along an axis of one sample).

    function layout_real64(field) result(layout)
        real(c_double), dimension(:, :, :), intent(in), asynchronous :: field
        type(sample_layout) :: layout
        integer(c_int64_t) :: n(3), second(3)
        n = shape(field, kind=c_int64_t)
        if (any(n == 0)) then
            layout = empty_layout(n)
            return
        end if
        second = min(2_c_int64_t, n)
        layout = array_layout(n, is_contiguous(field), storage_size(field), &
                              c_address(field(1, 1, 1)), c_address(field(second(1), 1, 1)), &
                              c_address(field(1, second(2), 1)), c_address(field(1, 1, second(3))))
    end function layout_real64

    function layout_real32(field) result(layout)
        real(c_float), dimension(:, :, :), intent(in), asynchronous :: field
        type(sample_layout) :: layout
        integer(c_int64_t) :: n(3), second(3)
        n = shape(field, kind=c_int64_t)
        if (any(n == 0)) then
            layout = empty_layout(n)
            return
        end if
        second = min(2_c_int64_t, n)
        layout = array_layout(n, is_contiguous(field), storage_size(field), &
                              c_address(field(1, 1, 1)), c_address(field(second(1), 1, 1)), &
                              c_address(field(1, second(2), 1)), c_address(field(1, 1, second(3))))
    end function layout_real32

    function layout_int16(field) result(layout)
        integer(c_int16_t), dimension(:, :, :), intent(in), asynchronous :: field
        type(sample_layout) :: layout
        integer(c_int64_t) :: n(3), second(3)
        n = shape(field, kind=c_int64_t)
        if (any(n == 0)) then
            layout = empty_layout(n)
            return
        end if
        second = min(2_c_int64_t, n)
        layout = array_layout(n, is_contiguous(field), storage_size(field), &
                              c_address(field(1, 1, 1)), c_address(field(second(1), 1, 1)), &
                              c_address(field(1, second(2), 1)), c_address(field(1, 1, second(3))))
    end function layout_int16

    function layout_int8(field) result(layout)
        integer(c_int8_t), dimension(:, :, :), intent(in), asynchronous :: field
        type(sample_layout) :: layout
        integer(c_int64_t) :: n(3), second(3)
        n = shape(field, kind=c_int64_t)
        if (any(n == 0)) then
            layout = empty_layout(n)
            return
        end if
        second = min(2_c_int64_t, n)
        layout = array_layout(n, is_contiguous(field), storage_size(field), &
                              c_address(field(1, 1, 1)), c_address(field(second(1), 1, 1)), &
                              c_address(field(1, second(2), 1)), c_address(field(1, 1, second(3))))
    end function layout_int8

    ! The layout of an array of `extents` samples of `sample_bits` bits from the addresses of its
    ! first element and of its neighbours along x, y and z. A contiguous array needs no strides.
    ! A reversed section yields a negative stride, which the C API refuses with a message naming
    ! it. A distance that is not a whole number of samples (a component of a SEQUENCE type with
    ! mixed kinds) becomes stride 0, which the C API refuses too rather than read wrong samples.
    function array_layout(extents, contiguous, sample_bits, first, next_x, next_y, next_z) &
        result(layout)
        integer(c_int64_t), intent(in) :: extents(3)
        logical, intent(in) :: contiguous
        integer, intent(in) :: sample_bits
        type(c_ptr), intent(in) :: first, next_x, next_y, next_z
        type(sample_layout) :: layout

        layout%data = first
        layout%dims = extents
        layout%contiguous = contiguous
        if (contiguous) return
        layout%strides(1) = stride_samples(extents(1), first, next_x, sample_bits / 8)
        layout%strides(2) = stride_samples(extents(2), first, next_y, sample_bits / 8)
        layout%strides(3) = stride_samples(extents(3), first, next_z, sample_bits / 8)
    end function array_layout

    function stride_samples(extent, first, next, sample_bytes) result(stride)
        integer(c_int64_t), intent(in) :: extent
        type(c_ptr), intent(in) :: first, next
        integer, intent(in) :: sample_bytes
        integer(c_int64_t) :: stride
        integer(c_intptr_t) :: distance_bytes

        stride = 1  ! never used along an axis of one sample
        if (extent == 1) return
        distance_bytes = transfer(next, distance_bytes) - transfer(first, distance_bytes)
        stride = 0
        if (mod(distance_bytes, int(sample_bytes, c_intptr_t)) == 0) &
            stride = int(distance_bytes / sample_bytes, c_int64_t)
    end function stride_samples

    function empty_layout(extents) result(layout)
        integer(c_int64_t), intent(in) :: extents(3)
        type(sample_layout) :: layout
        layout%data = c_loc(no_samples)
        layout%dims = extents
    end function empty_layout

    ! The strides argument of the C API: NULL for a contiguous array, else `strides` (the
    ! caller's copy of layout%strides, which needs the TARGET attribute for c_loc).
    function strides_pointer(layout, strides) result(pointer)
        type(sample_layout), intent(in) :: layout
        integer(c_int64_t), dimension(3), intent(in), target :: strides
        type(c_ptr) :: pointer
        pointer = c_null_ptr
        if (.not. layout%contiguous) pointer = c_loc(strides)
    end function strides_pointer

    function int16_type(unsigned) result(scalar_type)
        logical, intent(in), optional :: unsigned
        integer(c_int) :: scalar_type
        scalar_type = INSITU_INT16
        if (present(unsigned)) then
            if (unsigned) scalar_type = INSITU_UINT16
        end if
    end function int16_type

    function world_origin(origin) result(world)
        real(c_double), dimension(3), intent(in), optional :: origin
        real(c_double) :: world(3)
        world = 0.0_c_double
        if (present(origin)) world = origin
    end function world_origin

    function world_spacing(spacing) result(world)
        real(c_double), dimension(3), intent(in), optional :: spacing
        real(c_double) :: world(3)
        world = 1.0_c_double
        if (present(spacing)) world = spacing
    end function world_spacing

    function layer_counts(ghosts) result(layers)
        integer, dimension(3), intent(in), optional :: ghosts
        integer(c_int64_t) :: layers(3)
        layers = 0_c_int64_t
        if (present(ghosts)) layers = int(ghosts, c_int64_t)
    end function layer_counts

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
