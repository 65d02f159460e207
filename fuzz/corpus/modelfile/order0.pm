# fitted by pmfit from examples/sim_gem.dat (joint fit, both pier sides)
# N = 300, sigma = 13.454562 arcsec
pm-model 3
mount equatorial
order 0
latitude 0.8360127117052838
terms 6
# name k l m value_rad
term a 1 0 0 0.00053655218354744681
term b 2 0 0 -0.00063683471308167072
term c' 3 0 0 0.0058347550725724225
term d 4 0 0 3.8281959485422234e-05
term e' 5 0 0 -0.0020352629478499295
term i 6 0 0 -0.00027740282391895281
end
