!> fortran_api_test PREFIX: the Fortran module (adaptors/c/insitu.f90) on arrays declared without
!> the TARGET attribute. One integer-valued field, exactly representable in every type the module
!> takes, is handed over in many ways (allocatable and automatic arrays, sections that are not
!> contiguous along x, y or z, one filled in only after it was handed over, ghost layers, real64,
!> real32, int16, unsigned int16 and int8, blocks with ghosts_low/ghosts_high, cell centring),
!> each to an instrument of its own that writes the archive PREFIX<case>.cdb. fortran_api.cmake
!> then checks that each archive's previews equal those of the contiguous real64 array
!> ("contiguous"; the cell-centred blocks against "cell"): a copy, or a wrong address, stride,
!> ghost count, type or block origin, would change them. Along the way it checks insitu_selects,
!> the error statuses of bad arrays and that errors name the Fortran entry.
!> Exits 0 when every call returned what it should, 1 otherwise (each failure on stderr), 2 for
!> bad arguments.
program fortran_api_test
    use, intrinsic :: iso_c_binding, only: c_double, c_float, c_int, c_int16_t, c_int64_t, c_int8_t
    use, intrinsic :: iso_fortran_env, only: error_unit
    use insitu
    implicit none

    ! Samples per axis: all different, so that a transposed array changes the pictures.
    integer, parameter :: nx = 12, ny = 10, nz = 8
    integer, parameter :: half = nz / 2   ! the blocks cases split z here
    real(c_double), parameter :: spacing = 1.0d0 / 16
    real(c_double), parameter :: grid_spacing(3) = [spacing, spacing, spacing]
    ! Outside the field's range [0, 100]: where it is read by mistake, the transfer function
    ! shows it at full opacity.
    real(c_double), parameter :: garbage = 1000.0d0

    real(c_double), allocatable :: field(:, :, :)        ! the reference, contiguous
    real(c_double), allocatable :: padded(:, :, :)       ! field at padded(2:nx + 1, :, 1::2)
    real(c_double), allocatable :: with_ghosts(:, :, :)  ! field inside one ghost layer
    ! Shaped like padded, filled in after it is handed over. ASYNCHRONOUS, so that the compiler
    ! may not move that write past insitu_execute (adaptors/c/insitu.f90, "Lifetime").
    real(c_double), allocatable, asynchronous :: late(:, :, :)
    real(c_float), allocatable :: field32(:, :, :)       ! field at field32(:, 1::2, :)
    integer(c_int16_t), allocatable :: field16(:, :, :)
    integer(c_int16_t), allocatable :: wide16(:, :, :)   ! field at wide16(:, 2:ny + 1, :)
    integer(c_int8_t), allocatable :: field8(:, :, :)
    type(insitu_instrument) :: instrument
    character(len=:), allocatable :: prefix
    character(len=4096) :: argument
    integer(c_int) :: status
    integer :: failures

    if (command_argument_count() /= 1) then
        write (error_unit, '(a)') "usage: fortran_api_test PREFIX"
        stop 2, quiet=.true.
    end if
    call get_command_argument(1, argument)
    prefix = trim(argument)
    failures = 0

    call make_fields()

    if (start("contiguous")) then
        status = insitu_set_field(instrument, "v", field, spacing=grid_spacing)
        call finish("contiguous", status)
    end if
    if (start("section")) then
        ! Offset along x, every other sample along z: strides (1, nx + 2, 2 (nx + 2) ny).
        status = insitu_set_field(instrument, "v", padded(2:nx + 1, :, 1:2 * nz:2), &
                                  spacing=grid_spacing)
        call finish("section", status)
    end if
    if (start("in_place")) then
        ! Zero-copy, checked: the section holds garbage when it is handed over and the field
        ! only afterwards, so the pictures match only if insitu_execute reads the array itself.
        status = insitu_set_field(instrument, "v", late(2:nx + 1, :, 1:2 * nz:2), &
                                  spacing=grid_spacing)
        late(2:nx + 1, :, 1:2 * nz:2) = field
        call finish("in_place", status)
    end if
    if (start("ghosts")) then
        status = insitu_set_field(instrument, "v", with_ghosts, spacing=grid_spacing, &
                                  ghosts=[1, 1, 1])
        call finish("ghosts", status)
    end if
    call automatic_case([nx, ny, nz])
    if (start("real32")) then
        status = insitu_set_field(instrument, "v", field32(:, 1:2 * ny:2, :), &
                                  spacing=grid_spacing)
        call finish("real32", status)
    end if
    if (start("int16")) then
        status = insitu_set_field(instrument, "v", field16, spacing=grid_spacing)
        call finish("int16", status)
    end if
    if (start("uint16")) then
        status = insitu_set_field(instrument, "v", wide16(:, 2:ny + 1, :), spacing=grid_spacing, &
                                  unsigned=.true.)
        call finish("uint16", status)
    end if
    if (start("uint8")) then
        status = insitu_set_field(instrument, "v", field8, spacing=grid_spacing)
        call finish("uint8", status)
    end if
    if (start("blocks")) then
        ! The low half in z as the whole array less its high layers; the high half as a section
        ! that starts one layer lower, skipped as a low ghost (ghosts_high given: it defaults to
        ! ghosts_low).
        status = insitu_add_block(instrument, "v", field, spacing=grid_spacing, &
                                  ghosts_high=[0, 0, nz - half])
        if (status == INSITU_OK) &
            status = insitu_add_block(instrument, "v", field(:, :, half:nz), &
                                      origin=[0.0d0, 0.0d0, half * spacing], &
                                      spacing=grid_spacing, ghosts_low=[0, 0, 1], &
                                      ghosts_high=[0, 0, 0])
        call finish("blocks", status)
    end if
    if (start("cell")) then
        status = insitu_add_block(instrument, "v", field, spacing=grid_spacing, &
                                  centering=INSITU_CELL)
        call finish("cell", status)
    end if
    if (start("cell_blocks")) then
        status = insitu_add_block(instrument, "v", field(:, :, 1:half), spacing=grid_spacing, &
                                  centering=INSITU_CELL)
        if (status == INSITU_OK) &
            status = insitu_add_block(instrument, "v", field(:, :, half + 1:nz), &
                                      origin=[0.0d0, 0.0d0, half * spacing], &
                                      spacing=grid_spacing, centering=INSITU_CELL)
        call finish("cell_blocks", status)
    end if
    call check_errors()

    deallocate (field, padded, late, with_ghosts, field32, field16, wide16, field8, prefix)
    if (failures /= 0) then
        write (error_unit, '(a, i0, a)') "fortran_api_test: ", failures, " failures"
        stop 1, quiet=.true.
    end if
    write (*, '(a)') "fortran_api_test: every call returned what it should"

contains

    !> The field, an off-centre Gaussian rounded to whole numbers in [0, 100], and its copies.
    subroutine make_fields()
        integer :: i, j, k
        real(c_double) :: r2

        allocate (field(nx, ny, nz))
        do k = 1, nz
            do j = 1, ny
                do i = 1, nx
                    r2 = ((i - 4.0d0) / 4)**2 + ((j - 6.5d0) / 3)**2 + ((k - 3.0d0) / 3)**2
                    field(i, j, k) = anint(100 * exp(-r2))
                end do
            end do
        end do
        allocate (padded(nx + 2, ny, 2 * nz), with_ghosts(0:nx + 1, 0:ny + 1, 0:nz + 1))
        padded = garbage
        padded(2:nx + 1, :, 1:2 * nz:2) = field
        allocate (late(nx + 2, ny, 2 * nz))
        late = garbage
        with_ghosts = garbage
        with_ghosts(1:nx, 1:ny, 1:nz) = field
        allocate (field32(nx, 2 * ny, nz))
        field32 = real(garbage, c_float)
        field32(:, 1:2 * ny:2, :) = real(field, c_float)
        field16 = int(field, c_int16_t)
        allocate (wide16(nx, ny + 3, nz))
        wide16 = int(garbage, c_int16_t)
        wide16(:, 2:ny + 1, :) = field16
        field8 = int(field, c_int8_t)
    end subroutine make_fields

    !> An automatic array (its bounds are the dummy `extents`): it lives until the subroutine
    !> returns, after insitu_execute.
    subroutine automatic_case(extents)
        integer, intent(in) :: extents(3)
        real(c_double) :: samples(extents(1), extents(2), extents(3))
        samples = field
        if (start("automatic")) then
            status = insitu_set_field(instrument, "v", samples, spacing=grid_spacing)
            call finish("automatic", status)
        end if
    end subroutine automatic_case

    !> Creates the instrument of `case_name` and runs step 1, which the cadence ("every": 2)
    !> skips: no field is set. .false. (the failure counted) when that went wrong.
    logical function start(case_name)
        character(len=*), intent(in) :: case_name
        integer(c_int) :: created
        start = .false.
        created = insitu_create_from_json(configuration(prefix//case_name//".cdb"), instrument)
        call expect(created, INSITU_OK, case_name, "insitu_create_from_json")
        if (created /= INSITU_OK) return
        ! Both specific procedures of insitu_selects: a default-kind and a 64-bit step.
        if (insitu_selects(instrument, 1)) call fail(case_name, "insitu_selects(1) is .true.")
        call expect(insitu_execute(instrument, 1, 0.5d0), INSITU_NOT_SELECTED, case_name, &
                    "insitu_execute(1)")
        if (.not. insitu_selects(instrument, 2_c_int64_t)) &
            call fail(case_name, "insitu_selects(2) is .false.")
        start = .true.
    end function start

    !> Checks the hand-over's status, runs the selected step 2 and finishes the archive.
    subroutine finish(case_name, hand_over_status)
        character(len=*), intent(in) :: case_name
        integer(c_int), intent(in) :: hand_over_status
        call expect(hand_over_status, INSITU_OK, case_name, "handing the field over")
        call expect(insitu_execute(instrument, 2, 1.0d0), INSITU_OK, case_name, "insitu_execute(2)")
        call expect(insitu_finalize(instrument), INSITU_OK, case_name, "insitu_finalize")
        call insitu_destroy(instrument)
    end subroutine finish

    !> Arrays the C API cannot take, errors naming the Fortran entry, and an instrument after
    !> insitu_finalize.
    subroutine check_errors()
        character(len=*), parameter :: case_name = "errors"
        character(len=:), allocatable :: message
        integer(c_int) :: created

        created = insitu_create_from_json(configuration(prefix//case_name//".cdb"), instrument)
        call expect(created, INSITU_OK, case_name, "insitu_create_from_json")
        if (created /= INSITU_OK) return
        call expect(insitu_set_field(instrument, "no_such_field", field), &
                    INSITU_ERROR_INVALID_ARGUMENT, case_name, "an unknown field name")
        message = insitu_last_error()
        if (index(message, "insitu_set_field") == 0 .or. index(message, "_strided") /= 0) &
            call fail(case_name, "the error does not name insitu_set_field: "//message)
        call expect(insitu_add_block(instrument, "no_such_field", field), &
                    INSITU_ERROR_INVALID_ARGUMENT, case_name, "an unknown block name")
        message = insitu_last_error()
        if (index(message, "insitu_add_block") == 0) &
            call fail(case_name, "the error does not name insitu_add_block: "//message)
        ! A reversed section has a negative stride along x; a zero-size array has no samples.
        call expect(insitu_set_field(instrument, "v", field(nx:1:-1, :, :)), &
                    INSITU_ERROR_INVALID_ARGUMENT, case_name, "a reversed section")
        call expect(insitu_set_field(instrument, "v", field(1:0, :, :)), &
                    INSITU_ERROR_INVALID_ARGUMENT, case_name, "a zero-size array")
        call expect(insitu_finalize(instrument), INSITU_OK, case_name, "insitu_finalize")
        if (insitu_selects(instrument, 2)) &
            call fail(case_name, "insitu_selects is .true. after insitu_finalize")
        call expect(insitu_execute(instrument, 2, 1.0d0), INSITU_ERROR_STATE, case_name, &
                    "insitu_execute after insitu_finalize")
        call insitu_destroy(instrument)
        call insitu_destroy(instrument)  ! a null handle: harmless
    end subroutine check_errors

    subroutine expect(actual, expected, case_name, what)
        integer(c_int), intent(in) :: actual, expected
        character(len=*), intent(in) :: case_name, what
        if (actual /= expected) &
            call fail(case_name, what//": "//insitu_status_name(actual)//" instead of "// &
                      insitu_status_name(expected)//" ("//insitu_last_error()//")")
    end subroutine expect

    subroutine fail(case_name, message)
        character(len=*), intent(in) :: case_name, message
        write (error_unit, '(4a)') "fortran_api_test: ", case_name, ": ", message
        failures = failures + 1
    end subroutine fail

    !> Two 32x32 views of the field's box, a transfer function over [0, 100] with opacity per
    !> 0.1 world units (the box is 0.7 wide), every 2nd step, into `archive`.
    function configuration(archive) result(json)
        character(len=*), intent(in) :: archive
        character(len=:), allocatable :: json
        json = '{"fields": ["v"],' // &
               ' "views": [{"azimuth": 30, "elevation": 20, "size": [32, 32]},' // &
               '  {"azimuth": 120, "elevation": -10, "camera": "perspective", "fov": 30,' // &
               '   "size": [32, 32]}],' // &
               ' "transfer_function": {"points": [[0, 0, 0, 1, 0], [30, 0, 1, 0, 0.3],' // &
               '  [100, 1, 0, 0, 0.9]], "unit_length": 0.1},' // &
               ' "layers": "auto", "intervals": {"count": 4, "mode": "uniform"},' // &
               ' "every": 2, "archive": "' // json_escaped(archive) // '",' // &
               ' "writer": {"queue": 2, "when_full": "block"}}'
    end function configuration

    !> `text` with JSON's string escapes for '"' and '\'.
    function json_escaped(text) result(escaped)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: escaped
        integer :: i
        escaped = ""
        do i = 1, len(text)
            if (text(i:i) == '"' .or. text(i:i) == '\') escaped = escaped//'\'
            escaped = escaped//text(i:i)
        end do
    end function json_escaped

end program fortran_api_test
